// The Impetus viewer page: plays a run exported by `impetus run --out run.glb` (README.md, "Seeing a run").
// The run's binary glTF sits in the page as base64 (#impetus-run); everything the page shows besides the
// motion is read from the glTF's `extras` (gltf_export.cpp writes them): per moving body its velocity
// and angular velocity per sample, per sample the energies, the deepest penetration and the contacts.
// Options after '#' in the address fix a view (data.js, parseOptions). The page reports its state as
// JSON in #impetus-status for its headless test (tests/cli/test_viewer.cpp).
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import {
  decodeBase64, parseOptions, sampleIndex, interpolate, contactOffsets, contactsAt, length3, energyCurves,
  formatQuantity,
} from './data.js';
import { drawPlot, plotTime, kCurves, kPenetrationColour } from './plot.js';

const kFov = 45;            // vertical field of view (degrees); the headless test projects with it too
const kMaxArrows = 2000;    // contacts drawn at one time, at most
const $ = (id) => document.getElementById(id);

/** The float values of an accessor the extras name, or null. */
async function accessor(parser, index) {
  if (!Number.isInteger(index)) return null;
  const attribute = await parser.getDependency('accessor', index);
  return attribute.array;
}

/** Everything the page knows about the run once the glTF is parsed. */
async function loadRun(bytes) {
  const gltf = await new GLTFLoader().parseAsync(bytes.buffer, '');
  const extras = gltf.parser.json.asset.extras ?? {};
  const series = extras.series ?? {};
  const contacts = extras.contacts ?? {};
  const bodies = [];
  for (const object of gltf.scene.children) {
    const data = object.userData ?? {};
    bodies.push({
      object,
      name: data.name ?? object.name,
      mass: data.mass,
      fixed: Boolean(data.fixed),
      shape: data.shape ?? '?',
      velocity: await accessor(gltf.parser, data.velocity),
      angularVelocity: await accessor(gltf.parser, data.angular_velocity),
    });
  }
  const times = (await accessor(gltf.parser, series.times)) ?? new Float32Array(0);
  const counts = await accessor(gltf.parser, contacts.counts);
  return {
    gltf,
    extras,
    bodies,
    times,
    clip: gltf.animations[0] ?? null,
    kinetic: await accessor(gltf.parser, series.kinetic_energy),
    potential: await accessor(gltf.parser, series.potential_energy),
    penetration: await accessor(gltf.parser, series.penetration),
    contacts: {
      complete: contacts.complete !== false,
      offsets: counts ? contactOffsets(counts) : new Uint32Array(1),
      points: await accessor(gltf.parser, contacts.points),
      normal: await accessor(gltf.parser, contacts.normal_impulses),
      tangent: await accessor(gltf.parser, contacts.tangent_impulses),
    },
  };
}

/** 'Up' is against gravity (+z when there is none). */
function upOf(extras) {
  const g = new THREE.Vector3().fromArray(extras.gravity ?? [0, 0, -9.81]);
  return g.lengthSq() > 0 ? g.negate().normalize() : new THREE.Vector3(0, 0, 1);
}

/** A sphere around every body but the planes, over the whole run. */
function runBounds(run) {
  const box = new THREE.Box3();
  for (const body of run.bodies) {
    if (body.shape === 'plane') continue;
    const sphere = new THREE.Box3().setFromObject(body.object).getBoundingSphere(new THREE.Sphere());
    box.expandByPoint(body.object.position.clone().addScalar(sphere.radius));
    box.expandByPoint(body.object.position.clone().subScalar(sphere.radius));
    const track = run.clip?.tracks.find((k) => k.name === `${body.object.name}.position`);
    if (!track) continue;
    const radius = sphere.radius + sphere.center.distanceTo(body.object.position);
    for (let i = 0; i < track.values.length; i += 3) {
      const p = new THREE.Vector3().fromArray(track.values, i);
      box.expandByPoint(p.clone().addScalar(radius));
      box.expandByPoint(p.clone().subScalar(radius));
    }
  }
  if (box.isEmpty()) box.setFromCenterAndSize(new THREE.Vector3(), new THREE.Vector3(10, 10, 10));
  return box.getBoundingSphere(new THREE.Sphere());
}

function main(run, options) {
  const view = $('view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(window.innerWidth, window.innerHeight);
  view.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x20242b);
  scene.add(run.gltf.scene);
  const up = upOf(run.extras);
  const sky = new THREE.HemisphereLight(0xffffff, 0x404040, 1.6);
  sky.position.copy(up);
  scene.add(sky);
  const sun = new THREE.DirectionalLight(0xffffff, 1.4);
  scene.add(sun);

  // The camera: from the link, or looking at the whole run from the side and a little above.
  const bounds = runBounds(run);
  const camera = new THREE.PerspectiveCamera(kFov, window.innerWidth / window.innerHeight, 0.01, 1000);
  camera.up.copy(up);
  const side = new THREE.Vector3(1, 0, 0).cross(up);
  if (side.lengthSq() < 1e-6) side.set(0, 1, 0).cross(up);
  const across = new THREE.Vector3().crossVectors(side, up);
  const target = bounds.center.clone();
  const distance = bounds.radius / Math.sin(THREE.MathUtils.degToRad(kFov / 2)) * 1.05;
  camera.position.copy(target).addScaledVector(
    side.normalize().multiplyScalar(0.85).addScaledVector(up, 0.4).addScaledVector(across.normalize(), -0.3).normalize(),
    distance);
  if (options.camera) {
    camera.position.fromArray(options.camera, 0);
    target.fromArray(options.camera, 3);
  }
  camera.far = Math.max(1000, 20 * (distance + bounds.radius));
  camera.near = camera.far / 1e5;
  camera.updateProjectionMatrix();
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(target);
  controls.update();
  sun.position.copy(camera.position).addScaledVector(up, distance);

  // The animation, set to any time by hand (the mixer's own clock is not used).
  const duration = run.times.length ? run.times[run.times.length - 1] : 0;
  const mixer = new THREE.AnimationMixer(run.gltf.scene);
  const action = run.clip ? mixer.clipAction(run.clip) : null;
  if (action) {
    action.setLoop(THREE.LoopOnce, 1);
    action.clampWhenFinished = true;
    action.play();
  }
  const state = { time: options.time ?? 0, playing: options.time === null, speed: options.speed, selected: null };

  // Contacts: a pool of arrows (normal impulse, yellow; tangential, cyan) and a point each.
  const arrows = new THREE.Group();
  scene.add(arrows);
  const normalArrows = [];
  const tangentArrows = [];
  let largestImpulse = 0;
  if (run.contacts.normal) {
    for (let i = 0; i < run.contacts.normal.length / 3; ++i) largestImpulse = Math.max(largestImpulse, length3(run.contacts.normal, i));
  }
  const arrowLength = (p) => (largestImpulse > 0 ? 0.25 * bounds.radius * Math.sqrt(p / largestImpulse) : 0);
  const arrow = (pool, i, colour) => {
    while (pool.length <= i) {
      const a = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, colour);
      a.line.material.depthTest = false;
      a.cone.material.depthTest = false;
      a.renderOrder = 1;
      arrows.add(a);
      pool.push(a);
    }
    return pool[i];
  };
  $('contacts').checked = options.contacts;
  $('contacts').disabled = !run.contacts.points;

  function showContacts() {
    for (const a of [...normalArrows, ...tangentArrows]) a.visible = false;
    if (!$('contacts').checked || !run.contacts.points) return 0;
    const [begin, end] = contactsAt(run.times, run.contacts.offsets, state.time);
    const shown = Math.min(end - begin, kMaxArrows);
    const point = new THREE.Vector3();
    const direction = new THREE.Vector3();
    for (let k = 0; k < shown; ++k) {
      const c = begin + k;
      point.fromArray(run.contacts.points, 3 * c);
      for (const [values, pool, colour] of [[run.contacts.normal, normalArrows, 0xffd54f],
                                            [run.contacts.tangent, tangentArrows, 0x4dd0e1]]) {
        const p = length3(values, c);
        const a = arrow(pool, k, colour);
        if (!(p > 0)) continue;
        direction.fromArray(values, 3 * c).divideScalar(p);
        const l = Math.max(arrowLength(p), 0.02 * bounds.radius);
        a.position.copy(point);
        a.setDirection(direction);
        a.setLength(l, 0.25 * l, 0.12 * l);
        a.visible = true;
      }
    }
    return end - begin;
  }

  // The clicked body: name, mass, shape, and its state at the current time.
  const raycaster = new THREE.Raycaster();
  const bodyOf = (object) => run.bodies.find((b) => {
    for (let o = object; o; o = o.parent) if (o === b.object) return true;
    return false;
  });
  let pressedAt = null;
  renderer.domElement.addEventListener('pointerdown', (e) => { pressedAt = [e.clientX, e.clientY]; });
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!pressedAt || Math.hypot(e.clientX - pressedAt[0], e.clientY - pressedAt[1]) > 4) return;  // a drag
    const pointer = new THREE.Vector2((e.clientX / window.innerWidth) * 2 - 1, -(e.clientY / window.innerHeight) * 2 + 1);
    raycaster.setFromCamera(pointer, camera);
    const hit = raycaster.intersectObject(run.gltf.scene, true).find((h) => h.object.isMesh);
    select(hit ? bodyOf(hit.object) : null);
  });
  function select(body) {
    if (state.selected) state.selected.object.traverse((o) => o.material?.emissive?.setHex(0x000000));
    state.selected = body ?? null;
    if (state.selected) state.selected.object.traverse((o) => o.material?.emissive?.setHex(0x2a2a2a));
    $('info').style.display = state.selected ? 'block' : 'none';
  }
  if (options.select !== null) {
    const body = run.bodies.find((b) => b.name === options.select);
    if (!body) throw new Error(`#select=${options.select}: no body of that name in this run`);
    select(body);
  }
  function showInfo() {
    const body = state.selected;
    if (!body) return null;
    const rows = [['body', body.name], ['shape', body.shape],
                  ['mass', body.fixed ? 'fixed' : formatQuantity(body.mass, 'kg', 4)]];
    const p = body.object.position;
    rows.push(['position', [p.x, p.y, p.z].map((x) => x.toFixed(3)).join(', ') + ' m']);
    if (body.velocity) {
      const v = interpolate(run.times, body.velocity, 3, state.time);
      const w = interpolate(run.times, body.angularVelocity, 3, state.time);
      rows.push(['velocity', v.map((x) => x.toFixed(3)).join(', ') + ' m/s']);
      rows.push(['speed', formatQuantity(Math.hypot(...v), 'm/s')]);
      rows.push(['angular velocity', w.map((x) => x.toFixed(3)).join(', ') + ' rad/s']);
    }
    const table = document.createElement('table');
    for (const [key, value] of rows) {
      const tr = table.insertRow();
      tr.insertCell().textContent = key;
      tr.insertCell().textContent = value;
    }
    $('info').replaceChildren(table);
    return {
      name: body.name,
      mass: body.mass,
      position: [p.x, p.y, p.z],
      velocity: body.velocity ? interpolate(run.times, body.velocity, 3, state.time) : null,
    };
  }

  // The plot and its legend.
  const curves = run.kinetic && run.potential ? energyCurves(run.kinetic, run.potential) : null;
  const legend = curves ? kCurves.map((c) => `<span style="color:${c.colour}">— ${c.label} (J)</span>`) : [];
  if (run.penetration) legend.push(`<span style="color:${kPenetrationColour}">— deepest penetration (mm)</span>`);
  $('legend').innerHTML = legend.join('');
  const showPlot = () => { $('chart').style.display = curves && $('show-plot').checked ? 'block' : 'none'; };
  $('show-plot').disabled = !curves;
  $('show-plot').addEventListener('change', showPlot);
  showPlot();
  const seek = (time) => {
    state.time = Math.min(Math.max(time, 0), duration);
    render();
  };
  $('plot').addEventListener('pointerdown', (e) => seek(plotTime($('plot'), run.times, e.clientX, Boolean(run.penetration))));

  // Controls.
  const play = (on) => {
    state.playing = on && duration > 0;
    $('play').textContent = state.playing ? 'Pause' : 'Play';
  };
  $('play').addEventListener('click', () => {
    if (!state.playing && state.time >= duration) state.time = 0;
    play(!state.playing);
  });
  $('speed').value = String(state.speed);
  if ($('speed').value !== String(state.speed)) {
    const option = new Option(`${state.speed}×`, String(state.speed), true, true);
    $('speed').add(option);
  }
  $('speed').addEventListener('change', () => { state.speed = Number($('speed').value); });
  $('scrubber').addEventListener('input', () => {
    play(false);
    seek((Number($('scrubber').value) / 1000) * duration);
  });
  $('contacts').addEventListener('change', () => render());
  window.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
    if (e.code === 'Space') {
      e.preventDefault();
      $('play').click();
    } else if (e.code === 'ArrowRight' || e.code === 'ArrowLeft') {
      play(false);
      const i = sampleIndex(run.times, state.time) + (e.code === 'ArrowRight' ? 1 : -1);
      seek(run.times[Math.min(Math.max(i, 0), run.times.length - 1)] ?? 0);
    }
  });
  window.addEventListener('resize', () => {
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(window.innerWidth, window.innerHeight);
    render();
  });
  $('scene-name').textContent = run.extras.impetus_scene ?? '';
  const modules = run.extras.modules ?? {};
  $('modules').textContent = `${modules.integrator} · ${modules.detector} · ${modules.resolver} · dt ${run.extras.dt} s` +
      (run.contacts.complete ? '' : ' · contacts not all recorded (memory cap)');
  play(state.playing);

  let contactsShown = 0;
  function render() {
    if (action) {
      action.paused = false;
      action.enabled = true;
      action.time = Math.min(state.time, run.clip.duration);
      mixer.update(0);
    }
    contactsShown = showContacts();
    controls.update();
    renderer.render(scene, camera);
    $('clock').textContent = `t = ${state.time.toFixed(3)} s / ${duration.toFixed(3)} s`;
    $('scrubber').value = String(duration > 0 ? Math.round((state.time / duration) * 1000) : 0);
    if (curves && $('show-plot').checked) drawPlot($('plot'), run.times, curves, run.penetration, state.time);
    selectedInfo = showInfo();
    report('ready');
  }
  let selectedInfo = null;
  function report(phase) {
    $('impetus-status').textContent = JSON.stringify({
      state: phase,
      errors: window.impetusErrors,
      warnings: window.impetusWarnings,
      time: state.time,
      playing: state.playing,
      duration,
      samples: run.times.length,
      bodies: run.bodies.length,
      contacts_shown: contactsShown,
      selected: selectedInfo,
      width: window.innerWidth,
      height: window.innerHeight,
      camera: [...camera.position.toArray(), ...controls.target.toArray()],
      fov: kFov,
    });
  }

  let last = performance.now();
  renderer.setAnimationLoop((now) => {
    // The first frame's time can precede the clock read above: never step backwards, nor more than 0.1 s.
    const elapsed = Math.min(Math.max((now - last) / 1000, 0), 0.1);
    last = now;
    if (state.playing) {
      state.time += elapsed * state.speed;
      if (state.time >= duration) {
        state.time = duration;
        play(false);
      }
    }
    render();
  });
  render();
}

async function start() {
  try {
    const options = parseOptions(window.location.hash);
    const run = await loadRun(decodeBase64($('impetus-run').textContent));
    main(run, options);
  } catch (error) {
    window.impetusErrors.push(String(error?.message ?? error));
    $('failure').textContent = `The run could not be shown: ${error?.message ?? error}`;
    $('failure').style.display = 'block';
    $('impetus-status').textContent = JSON.stringify({ state: 'failed', errors: window.impetusErrors });
  }
}

start();
