// Stable colours for polygon ids. The same id always gets the same colour,
// in the points, the filled surfaces, the outlines, the legend and the
// exports. Hues step by the golden angle so consecutive ids differ, and
// lightness alternates in three bands so neighbours with close hues still
// separate. No three.js here: the table is plain bytes.

/** Label of a point no polygon explained (the library's 0xFFFFFFFF). */
export const NONE = 0xffffffff;

const SIZE = 4096; // ids wrap around after this many; colours repeat, ids stay unique
const LUT = new Uint8Array(SIZE * 3);
// Ground polygons (road, sidewalks) get a muted version of their id's colour,
// so the large ground areas stay calm and the facades, walls and cars stand out.
const GROUND = new Uint8Array(SIZE * 3);

function hslToRgb(h, s, l) {
  const k = (n) => (n + h / 30) % 12;
  const a = s * Math.min(l, 1 - l);
  const f = (n) => l - a * Math.max(-1, Math.min(k(n) - 3, Math.min(9 - k(n), 1)));
  return [f(0), f(8), f(4)];
}

for (let i = 0; i < SIZE; i++) {
  const hue = (i * 137.50776405 + 18) % 360;
  const light = [0.62, 0.7, 0.55][i % 3];
  const sat = [0.78, 0.68, 0.72][(i >> 1) % 3];
  const [r, g, b] = hslToRgb(hue, sat, light);
  LUT[i * 3] = Math.round(r * 255);
  LUT[i * 3 + 1] = Math.round(g * 255);
  LUT[i * 3 + 2] = Math.round(b * 255);
  const [gr, gg, gb] = hslToRgb((hue * 0.35 + 185) % 360, 0.22 + 0.08 * (i % 3), 0.46 + 0.06 * ((i >> 1) % 3));
  GROUND[i * 3] = Math.round(gr * 255);
  GROUND[i * 3 + 1] = Math.round(gg * 255);
  GROUND[i * 3 + 2] = Math.round(gb * 255);
}

const table = (ground) => (ground ? GROUND : LUT);

/** `[r, g, b]` in 0..1 for a polygon id (`ground`: the muted ground colour). */
export function idColor(id, ground = false) {
  const t = table(ground);
  const j = (id % SIZE) * 3;
  return [t[j] / 255, t[j + 1] / 255, t[j + 2] / 255];
}

/** CSS colour string for a polygon id. */
export function idCss(id, ground = false) {
  const t = table(ground);
  const j = (id % SIZE) * 3;
  return `rgb(${t[j]}, ${t[j + 1]}, ${t[j + 2]})`;
}

/**
 * Fill `out` (Uint8 RGB, 3 bytes a point) from per-point `labels`: the
 * polygon's colour (muted for ids in the `ground` Set), or a grey for
 * unexplained points whose brightness follows the intensity (`points`,
 * stride 4, 4th value in 0..1 or 0..255).
 */
export function colorPoints(labels, points, n, out, ground = null) {
  // Intensity scale: Ouster and KITTI files use 0..1 or 0..255 or raw counts.
  let imax = 0;
  for (let i = 0; i < n; i += 97) imax = Math.max(imax, points[i * 4 + 3]);
  const iscale = imax > 1.5 ? 1 / imax : 1;
  for (let i = 0; i < n; i++) {
    const id = labels ? labels[i] : NONE;
    const o = i * 3;
    if (id === NONE) {
      const t = Math.min(1, Math.max(0, points[i * 4 + 3] * iscale));
      const g = 92 + Math.round(Math.sqrt(t) * 70);
      out[o] = g;
      out[o + 1] = g + 4;
      out[o + 2] = g + 12;
    } else {
      const t = ground && ground.has(id) ? GROUND : LUT;
      const j = (id % SIZE) * 3;
      out[o] = t[j];
      out[o + 1] = t[j + 1];
      out[o + 2] = t[j + 2];
    }
  }
}
