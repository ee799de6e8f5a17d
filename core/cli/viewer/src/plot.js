// The energy and penetration plot under the view: kinetic, potential (from the start) and total energy in
// joules on the left axis, the deepest penetration in millimetres on the right one, and a cursor at the
// current time. Plain 2D canvas drawing.
import { formatQuantity, range } from './data.js';

export const kCurves = [
  { key: 'kinetic', label: 'kinetic', colour: '#ffb74d' },
  { key: 'potential', label: 'potential − start', colour: '#64b5f6' },
  { key: 'total', label: 'total − start', colour: '#eeeeee' },
];
export const kPenetrationColour = '#ef5350';

/** Draws the curves over times; `penetration` in metres (null when the run has none). */
export function drawPlot(canvas, times, curves, penetration, t) {
  const ratio = window.devicePixelRatio || 1;
  const width = canvas.clientWidth;
  const height = canvas.clientHeight;
  if (canvas.width !== Math.round(width * ratio)) canvas.width = Math.round(width * ratio);
  if (canvas.height !== Math.round(height * ratio)) canvas.height = Math.round(height * ratio);
  const g = canvas.getContext('2d');
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  g.clearRect(0, 0, width, height);
  if (times.length < 2) return;

  const left = 48;
  const right = penetration ? 54 : 8;
  const top = 6;
  const bottom = 16;
  const t0 = times[0];
  const t1 = times[times.length - 1];
  const x = (time) => left + ((time - t0) / (t1 - t0)) * (width - left - right);
  const [lo, hi] = range(kCurves.map((c) => curves[c.key]));
  const y = (v) => top + (1 - (v - lo) / (hi - lo)) * (height - top - bottom);

  g.font = '10px system-ui, sans-serif';
  g.fillStyle = '#a8adb7';
  g.strokeStyle = '#3a3f48';
  g.lineWidth = 1;
  g.beginPath();
  g.moveTo(left, y(0));
  g.lineTo(width - right, y(0));
  g.stroke();
  g.textAlign = 'right';
  g.fillText(formatQuantity(hi, 'J', 2), left - 4, top + 8);
  g.fillText(formatQuantity(lo, 'J', 2), left - 4, height - bottom);
  g.textAlign = 'center';
  g.fillText(formatQuantity(t0, 's', 2), left, height - 3);
  g.fillText(formatQuantity(t1, 's', 2), width - right, height - 3);

  const stroke = (values, colour, map) => {
    g.strokeStyle = colour;
    g.beginPath();
    const step = Math.max(1, Math.floor(values.length / (2 * width)));  // at most two points per pixel
    for (let i = 0; i < values.length; i += step) {
      if (i === 0) g.moveTo(x(times[i]), map(values[i]));
      else g.lineTo(x(times[i]), map(values[i]));
    }
    g.stroke();
  };
  for (const c of kCurves) stroke(curves[c.key], c.colour, y);
  if (penetration) {
    const [, deepest] = range([penetration, [0]]);
    const yp = (v) => top + (1 - v / deepest) * (height - top - bottom);
    stroke(penetration, kPenetrationColour, yp);
    g.fillStyle = kPenetrationColour;
    g.textAlign = 'left';
    g.fillText(formatQuantity(deepest * 1e3, 'mm', 2), width - right + 3, top + 8);
    g.fillText('0', width - right + 3, height - bottom);
  }
  g.strokeStyle = '#ffffff';
  g.beginPath();
  g.moveTo(x(Math.min(Math.max(t, t0), t1)), top);
  g.lineTo(x(Math.min(Math.max(t, t0), t1)), height - bottom);
  g.stroke();
}

/** The time under a horizontal position of the plot (for seeking by clicking it). */
export function plotTime(canvas, times, clientX, hasPenetration) {
  const box = canvas.getBoundingClientRect();
  const left = 48;
  const right = hasPenetration ? 54 : 8;
  const s = (clientX - box.left - left) / (box.width - left - right);
  const t0 = times[0];
  const t1 = times[times.length - 1];
  return t0 + Math.min(Math.max(s, 0), 1) * (t1 - t0);
}
