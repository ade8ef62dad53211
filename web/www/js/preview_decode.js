// Turns a program.preview answer's base64 polylines into the arrays three.js draws: two
// vertices a segment (xyz, float32), a colour a vertex by the polyline's kind, and the source
// line and kind of each segment (for picking and for drawing the part already run). Used by the
// decode worker for large answers and on the page for small ones.

import {kindColor} from './preview_colors.js';

const littleEndian = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

function bytes(base64) {
  const text = atob(base64 ?? '');
  const out = new Uint8Array(text.length);
  for (let i = 0; i < text.length; ++i)
    out[i] = text.charCodeAt(i);
  return out;
}

function typed(base64, Type) {
  const raw = bytes(base64);
  const count = Math.floor(raw.length / Type.BYTES_PER_ELEMENT);
  if (littleEndian) return new Type(raw.buffer, 0, count);
  const view = new DataView(raw.buffer);
  const out = new Type(count);
  const get = Type === Float32Array ? (i) => view.getFloat32(i * 4, true) :
                                      (i) => view.getUint32(i * 4, true);
  for (let i = 0; i < count; ++i)
    out[i] = get(i);
  return out;
}

export function decodePreview(result) {
  const kinds = bytes(result.polyline_kind);
  const counts = typed(result.polyline_points, Uint32Array);
  const xyz = typed(result.xyz, Float32Array);
  const lines = typed(result.line, Uint32Array);
  const points = lines.length;
  let total = 0;
  for (const n of counts)
    total += n > 1 ? n - 1 : 0;
  const positions = new Float32Array(total * 6);
  const colors = new Float32Array(total * 6);
  const segLine = new Uint32Array(total);
  const segKind = new Uint8Array(total);
  let s = 0;
  let p = 0;
  for (let i = 0; i < counts.length; ++i) {
    const n = counts[i];
    const kindName = result.kinds?.[kinds[i]] ?? 'feed';
    const [r, g, b] = kindColor(kindName);
    for (let k = 1; k < n && p + k < points; ++k, ++s) {
      const a = (p + k - 1) * 3;
      const o = s * 6;
      positions[o] = xyz[a];
      positions[o + 1] = xyz[a + 1];
      positions[o + 2] = xyz[a + 2];
      positions[o + 3] = xyz[a + 3];
      positions[o + 4] = xyz[a + 4];
      positions[o + 5] = xyz[a + 5];
      colors[o] = colors[o + 3] = r;
      colors[o + 1] = colors[o + 4] = g;
      colors[o + 2] = colors[o + 5] = b;
      segLine[s] = lines[p + k];
      segKind[s] = kinds[i];
    }
    p += n;
  }
  return {
    positions: positions.subarray(0, s * 6),
    colors: colors.subarray(0, s * 6),
    segLine: segLine.subarray(0, s),
    segKind: segKind.subarray(0, s)
  };
}

// Decodes in place: the base64 strings are dropped, `decoded` holds the arrays.
export function decodeInPlace(result) {
  if (result.decoded || typeof result.xyz !== 'string') return result;
  result.decoded = decodePreview(result);
  for (const key of ['xyz', 'line', 'polyline_kind', 'polyline_points', 'polyline_frame'])
    delete result[key];
  return result;
}
