// The viewer's arithmetic on a run's samples, free of three.js and of the page, so that node can test it
// (test/data.test.js). Times are the animation's sample times (seconds, increasing); a run's per-sample
// values sit one sample after another, `width` numbers each.

/** The bytes of a base64 text (whitespace ignored). */
export function decodeBase64(text) {
  const binary = atob(text.replace(/\s+/g, ''));
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

/**
 * Options a link can carry after '#', for a fixed view (tests, screenshots, a shared link):
 * time=T (start paused at T seconds), camera=px,py,pz,tx,ty,tz (eye and target, world metres),
 * contacts (draw contacts), speed=S, select=NAME (show that body's information). Anything else is
 * ignored; a malformed value is an error.
 */
export function parseOptions(hash) {
  const options = { time: null, camera: null, contacts: false, speed: 1, select: null };
  const text = hash.startsWith('#') ? hash.slice(1) : hash;
  for (const part of text.split('&')) {
    if (!part) continue;
    const [key, value = ''] = part.split('=');
    const numbers = () => {
      const list = decodeURIComponent(value).split(',').map(Number);
      if (list.some((x) => !Number.isFinite(x))) throw new Error(`#${key}=${value}: not a list of numbers`);
      return list;
    };
    if (key === 'time') {
      [options.time] = numbers();
    } else if (key === 'camera') {
      options.camera = numbers();
      if (options.camera.length !== 6) throw new Error(`#camera=${value}: needs six numbers (eye and target)`);
    } else if (key === 'contacts') {
      options.contacts = value !== '0';
    } else if (key === 'select') {
      options.select = decodeURIComponent(value);
    } else if (key === 'speed') {
      [options.speed] = numbers();
      if (!(options.speed > 0)) throw new Error(`#speed=${value}: must be positive`);
    }
  }
  return options;
}

/** The index of the last sample at or before t (0 before the first, the last after the end). */
export function sampleIndex(times, t) {
  if (times.length === 0 || t <= times[0]) return 0;
  let lo = 0;
  let hi = times.length - 1;
  if (t >= times[hi]) return hi;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (times[mid] <= t) lo = mid;
    else hi = mid;
  }
  return lo;
}

/** The `width` values at time t, linearly interpolated between samples (as the glTF animation is). */
export function interpolate(times, values, width, t) {
  const i = sampleIndex(times, t);
  const out = new Array(width);
  const j = Math.min(i + 1, times.length - 1);
  const span = times[j] - times[i];
  const s = span > 0 ? Math.min(Math.max((t - times[i]) / span, 0), 1) : 0;
  for (let k = 0; k < width; ++k) out[k] = values[i * width + k] * (1 - s) + values[j * width + k] * s;
  return out;
}

/** Where each sample's contacts begin, from the count per sample (one more entry than counts). */
export function contactOffsets(counts) {
  const offsets = new Uint32Array(counts.length + 1);
  for (let i = 0; i < counts.length; ++i) offsets[i + 1] = offsets[i] + counts[i];
  return offsets;
}

/** The contacts [begin, end) recorded at the last sample at or before t. */
export function contactsAt(times, offsets, t) {
  if (times.length === 0 || offsets.length < 2) return [0, 0];
  const i = sampleIndex(times, t);
  return [offsets[i], offsets[i + 1]];
}

/** Euclidean length of the 3-vector at `index` of a flat array. */
export function length3(values, index) {
  const x = values[3 * index];
  const y = values[3 * index + 1];
  const z = values[3 * index + 2];
  return Math.sqrt(x * x + y * y + z * z);
}

/**
 * The curves the energy plot draws: kinetic energy, potential energy and their sum measured from the
 * first sample (what the run gained or lost), in joules.
 */
export function energyCurves(kinetic, potential) {
  const n = kinetic.length;
  const fromStart = new Float64Array(n);
  const total = new Float64Array(n);
  const u0 = n > 0 ? potential[0] : 0;
  for (let i = 0; i < n; ++i) {
    fromStart[i] = potential[i] - u0;
    total[i] = kinetic[i] + fromStart[i];
  }
  return { kinetic: Float64Array.from(kinetic), potential: fromStart, total };
}

/** The smallest and largest value over several curves, widened when they are equal. */
export function range(curves) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const curve of curves)
    for (const v of curve) {
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
  if (!Number.isFinite(lo)) return [0, 1];
  if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) {
    const pad = Math.max(Math.abs(hi) * 0.1, 1e-9);
    return [lo - pad, hi + pad];
  }
  return [lo, hi];
}

/** A number with `digits` significant digits and its unit, for labels ("2.35 m/s", "-0.5 J"). */
export function formatQuantity(value, unit, digits = 3) {
  if (!Number.isFinite(value)) return `${value} ${unit}`;
  const text = Math.abs(value) >= 1e-4 || value === 0 ? Number(value.toPrecision(digits)).toString()
                                                     : value.toExponential(digits - 1);
  return `${text} ${unit}`;
}
