// Small live line charts on a 2D canvas, one value per scan: the curves of
// the paper's Fig. 14 (polygon count, points sent to detection, total area)
// and the time per scan.

export class Sparkline {
  /**
   * @param {HTMLCanvasElement} canvas
   * @param {{ color: string, format: (v:number)=>string, valueEl?: HTMLElement, max?: number }} opts
   */
  constructor(canvas, { color, format, valueEl, max = 4000 }) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.color = color;
    this.format = format;
    this.valueEl = valueEl;
    this.max = max;
    this.values = [];
    this.dirty = true;
  }

  clear() {
    this.values.length = 0;
    this.dirty = true;
    if (this.valueEl) this.valueEl.textContent = '–';
  }

  push(v) {
    this.values.push(v);
    if (this.values.length > this.max) this.values.splice(0, this.values.length - this.max);
    if (this.valueEl) this.valueEl.textContent = this.format(v);
    this.dirty = true;
  }

  /** Redraw if something changed (call once per animation frame). */
  draw() {
    if (!this.dirty) return;
    this.dirty = false;
    const c = this.canvas;
    const dpr = Math.min(window.devicePixelRatio || 1, 2);
    const w = Math.max(1, Math.round(c.clientWidth * dpr));
    const h = Math.max(1, Math.round(c.clientHeight * dpr));
    if (c.width !== w || c.height !== h) {
      c.width = w;
      c.height = h;
    }
    const g = this.ctx;
    g.clearRect(0, 0, w, h);
    const vals = this.values;
    if (vals.length === 0) return;
    let hi = -Infinity;
    let lo = Infinity;
    for (const v of vals) {
      if (v > hi) hi = v;
      if (v < lo) lo = v;
    }
    lo = Math.min(0, lo);
    if (hi <= lo) hi = lo + 1;
    const pad = 2 * dpr;
    const n = Math.max(vals.length, 40); // short runs fill from the left
    const x = (i) => pad + (i / (n - 1)) * (w - 2 * pad);
    const y = (v) => h - pad - ((v - lo) / (hi - lo)) * (h - 2 * pad);
    // area
    const grad = g.createLinearGradient(0, 0, 0, h);
    grad.addColorStop(0, this.color + '55');
    grad.addColorStop(1, this.color + '00');
    g.beginPath();
    g.moveTo(x(0), h);
    for (let i = 0; i < vals.length; i++) g.lineTo(x(i), y(vals[i]));
    g.lineTo(x(vals.length - 1), h);
    g.closePath();
    g.fillStyle = grad;
    g.fill();
    // line
    g.beginPath();
    for (let i = 0; i < vals.length; i++) (i ? g.lineTo : g.moveTo).call(g, x(i), y(vals[i]));
    g.strokeStyle = this.color;
    g.lineWidth = 1.5 * dpr;
    g.lineJoin = 'round';
    g.stroke();
    // last value dot
    const lx = x(vals.length - 1);
    const ly = y(vals[vals.length - 1]);
    g.beginPath();
    g.arc(lx, ly, 2.2 * dpr, 0, Math.PI * 2);
    g.fillStyle = this.color;
    g.fill();
  }
}
