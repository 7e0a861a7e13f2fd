// Live plots under the view: kinetic, potential and total energy (J) and |L| (kg·m²/s)
// over the whole run, with a cursor at the frame shown. Plain 2D canvas: no library.
const COLOURS = { kinetic: '#1f77b4', potential: '#2ca02c', total: '#d62728', L: '#9467bd' };

function panel(parent, label, series, times) {
  const canvas = document.createElement('canvas');
  canvas.width = 360;
  canvas.height = 110;
  parent.appendChild(canvas);
  const g = canvas.getContext('2d');
  const all = series.flatMap((s) => s.values);
  let lo = Math.min(...all);
  let hi = Math.max(...all);
  if (hi - lo < 1e-9 * Math.max(1, Math.abs(hi))) { lo -= 0.5 * Math.max(1e-9, Math.abs(lo)); hi += 0.5 * Math.max(1e-9, Math.abs(hi)); }
  const pad = { l: 52, r: 8, t: 16, b: 16 };
  const t1 = times[times.length - 1] || 1;
  const X = (t) => pad.l + (t / t1) * (canvas.width - pad.l - pad.r);
  const Y = (v) => canvas.height - pad.b - ((v - lo) / (hi - lo)) * (canvas.height - pad.t - pad.b);
  return (frame) => {
    g.clearRect(0, 0, canvas.width, canvas.height);
    g.fillStyle = 'rgba(255,255,255,0.9)';
    g.fillRect(0, 0, canvas.width, canvas.height);
    g.font = '11px sans-serif';
    g.fillStyle = '#333';
    g.fillText(hi.toPrecision(4), 2, pad.t + 4);
    g.fillText(lo.toPrecision(4), 2, canvas.height - pad.b);
    let x = pad.l + 4;
    for (const s of series) {
      g.fillStyle = s.colour;
      g.fillText(s.name, x, 11);
      x += g.measureText(s.name).width + 12;
    }
    g.fillStyle = '#333';
    g.fillText(label, canvas.width - g.measureText(label).width - 4, 11);
    for (const s of series) {
      // The run so far solid, the rest faint.
      for (const [alpha, from, to] of [[0.25, frame, times.length - 1], [1, 0, frame]]) {
        g.globalAlpha = alpha;
        g.strokeStyle = s.colour;
        g.lineWidth = 1.5;
        g.beginPath();
        for (let k = from; k <= to; k++) (k === from ? g.moveTo : g.lineTo).call(g, X(times[k]), Y(s.values[k]));
        g.stroke();
      }
      g.globalAlpha = 1;
    }
    g.strokeStyle = '#555';
    g.beginPath();
    g.moveTo(X(times[frame]), pad.t);
    g.lineTo(X(times[frame]), canvas.height - pad.b);
    g.stroke();
  };
}

export function energyPlot(parent, data) {
  const e = data.energy;
  const draws = [
    panel(parent, 'energy (J)', [
      { name: 'kinetic', values: e.kinetic, colour: COLOURS.kinetic },
      { name: 'potential', values: e.potential, colour: COLOURS.potential },
      { name: 'total', values: e.total, colour: COLOURS.total },
    ], data.times),
    panel(parent, '|L| about the origin (kg·m²/s)', [
      { name: '|L|', values: e.angular_momentum, colour: COLOURS.L },
    ], data.times),
  ];
  return { cursor: (frame) => draws.forEach((d) => d(frame)) };
}
