// node --test core/cli/viewer/test: the viewer's arithmetic (src/data.js) against values worked out by hand.
import test from 'node:test';
import assert from 'node:assert/strict';
import {
  decodeBase64, parseOptions, sampleIndex, interpolate, contactOffsets, contactsAt, length3, energyCurves, range,
  formatQuantity,
} from '../src/data.js';

test('base64 decodes what Buffer encodes, whatever the padding', () => {
  for (const text of ['', 'a', 'ab', 'abc', 'glTF\u0002\u0000\u0000\u0000\u00ff']) {
    const bytes = Buffer.from(text, 'latin1');
    assert.deepEqual(Array.from(decodeBase64(bytes.toString('base64'))), Array.from(bytes));
  }
  assert.deepEqual(Array.from(decodeBase64('Z2x0\nRg==')), [0x67, 0x6c, 0x74, 0x46]);
});

test('link options: time, camera, contacts, speed; malformed values are errors', () => {
  assert.deepEqual(parseOptions(''), { time: null, camera: null, contacts: false, speed: 1, select: null });
  assert.deepEqual(parseOptions('#time=1.5&camera=0,-6,2,0,0,0.5&contacts&speed=2&select=box%201'),
                   { time: 1.5, camera: [0, -6, 2, 0, 0, 0.5], contacts: true, speed: 2, select: 'box 1' });
  assert.throws(() => parseOptions('#camera=1,2,3'), /six numbers/);
  assert.throws(() => parseOptions('#time=soon'), /not a list of numbers/);
  assert.throws(() => parseOptions('#speed=-1'), /positive/);
});

test('sample index: the last sample at or before t, clamped at both ends', () => {
  const times = [0, 0.1, 0.2, 0.4];
  assert.equal(sampleIndex(times, -1), 0);
  assert.equal(sampleIndex(times, 0), 0);
  assert.equal(sampleIndex(times, 0.15), 1);
  assert.equal(sampleIndex(times, 0.2), 2);
  assert.equal(sampleIndex(times, 0.39), 2);
  assert.equal(sampleIndex(times, 9), 3);
  assert.equal(sampleIndex([], 1), 0);
});

test('interpolation is linear between samples and exact on them', () => {
  const times = [0, 1, 3];
  const values = [0, 0, 0, 2, 4, 6, 6, 4, 2];  // three 3-vectors
  assert.deepEqual(interpolate(times, values, 3, 1), [2, 4, 6]);
  assert.deepEqual(interpolate(times, values, 3, 0.5), [1, 2, 3]);
  assert.deepEqual(interpolate(times, values, 3, 2), [4, 4, 4]);
  assert.deepEqual(interpolate(times, values, 3, 10), [6, 4, 2]);
});

test('contacts of a time: the counts of the samples before it are skipped', () => {
  const offsets = contactOffsets([2, 0, 3]);
  assert.deepEqual(Array.from(offsets), [0, 2, 2, 5]);
  const times = [0, 0.5, 1];
  assert.deepEqual(contactsAt(times, offsets, 0.2), [0, 2]);
  assert.deepEqual(contactsAt(times, offsets, 0.5), [2, 2]);
  assert.deepEqual(contactsAt(times, offsets, 7), [2, 5]);
  assert.deepEqual(contactsAt([], new Uint32Array(1), 0), [0, 0]);
});

test('energy curves: potential and total measured from the first sample', () => {
  // A 2 kg ball dropped from rest: K = m g d, U - U0 = -m g d, so the total stays 0.
  const g = 9.81;
  const drops = [0, 0.1, 0.4];
  const kinetic = drops.map((d) => 2 * g * d);
  const potential = drops.map((d) => 2 * g * (1 - d));
  const c = energyCurves(kinetic, potential);
  drops.forEach((d, i) => {
    assert.ok(Math.abs(c.potential[i] + 2 * g * d) < 1e-12);
    assert.ok(Math.abs(c.total[i]) < 1e-12);
  });
  assert.equal(length3([0, 0, 0, 3, 4, 12], 1), 13);
});

test('plot ranges span every curve and never collapse', () => {
  assert.deepEqual(range([[1, 3], [-2, 0]]), [-2, 3]);
  const [lo, hi] = range([[5, 5]]);
  assert.ok(lo < 5 && hi > 5);
  assert.deepEqual(range([]), [0, 1]);
  assert.equal(formatQuantity(2.3456, 'm/s'), '2.35 m/s');
  assert.equal(formatQuantity(0, 'J'), '0 J');
  assert.equal(formatQuantity(2e-6, 'm'), '2.00e-6 m');
});
