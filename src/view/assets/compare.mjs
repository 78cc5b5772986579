// The comparison mode: two samplers at the same budget, side by side, with their per-pixel
// error against the converged reference as heat maps on one shared scale, and both errors'
// spectra in one plot.
import { api } from './token.mjs';

const el = id => document.getElementById(id);
const sci = x => x.toExponential(2);

function figure(src, caption, onload) {
  const f = document.createElement('figure');
  const img = document.createElement('img');
  img.onload = onload;
  img.src = src;
  const c = document.createElement('figcaption');
  c.textContent = caption;
  f.appendChild(img); f.appendChild(c);
  return f;
}

function show(result) {
  const out = el('compare-result');
  out.innerHTML = '';
  out.dataset.images = '0';
  let loaded = 0;
  const count = () => { loaded++; out.dataset.images = String(loaded); };
  const est = e => `${sci(e.mean)} ± ${sci(e.se)}`;
  out.appendChild(figure(result.reference, `converged reference: 2 × ${result.reference_samples} stratified points, ` +
    `its own noise ${sci(result.reference_noise)}`, count));
  result.sides.forEach((s, i) => {
    const name = i === 0 ? 'A' : 'B';
    out.appendChild(figure(s.image, `${name}: ${s.sampler}, N = ${result.n} (seed 1), ${s.seconds.toPrecision(3)} s per render`, count));
    const pen = s.mse_penumbra ? `; penumbra (${result.penumbra_pixels} px) ${est(s.mse_penumbra)}` : '';
    out.appendChild(figure(s.heat, `${name} error: MSE ${est(s.mse)} (mean ± s.e. over ${result.seeds} seeds)${pen}; ` +
      `bias ${sci(s.bias[0])} (bound ${sci(s.bias[1])})`, count));
  });
  const share = s => `${s.sampler} ${s.perceived.low_band_share.toFixed(2)}`;
  const blurred = s => `${s.sampler} ${sci(s.perceived.lowpass_mse[1])}`;
  out.appendChild(figure(result.spectrum, `error spectra over the whole image (flat: white noise; rising: blue noise). ` +
    `Low band's share of the error power (1 for white noise): ${result.sides.map(share).join(', ')}; ` +
    `MSE blurred by 2 pixels: ${result.sides.map(blurred).join(', ')}`, count));
  if (result.heat_scale) {
    const p = document.createElement('p');
    p.className = 'note';
    p.textContent = `heat maps: per-pixel MSE on one log scale, dark 1e${result.heat_scale[0].toFixed(1)} to bright 1e${result.heat_scale[1].toFixed(1)}; ${result.seconds.toPrecision(3)} s in all`;
    out.appendChild(p);
  }
}

/** Fills the form's sampler menus and runs a comparison on submit; `settings()` gives the
 * render settings the comparison starts from. */
export function initCompare(samplers, settings) {
  const form = el('compare-form');
  for (const [name, pick] of [['a', 'random'], ['b', 'stratified']]) {
    const s = form.elements[name];
    for (const n of samplers) { const o = document.createElement('option'); o.textContent = n; s.appendChild(o); }
    s.value = pick;
  }
  form.addEventListener('submit', async e => {
    e.preventDefault();
    const f = form.elements;
    const s = settings();
    // The comparison chooses its own size, shadows, sampler and seed.
    for (const k of ['width', 'height', 'shadows', 'shadow_samples', 'sampler', 'seed']) delete s[k];
    const body = { settings: s, samplers: [f.a.value, f.b.value], n: Number(f.n.value), seeds: Number(f.seeds.value), size: Number(f.size.value) };
    el('compare-status').textContent = 'rendering…';
    el('compare-run').disabled = true;
    try {
      show(await api('/api/compare', { method: 'POST', body: JSON.stringify(body) }));
      el('compare-status').textContent = '';
    } catch (err) {
      el('compare-status').textContent = `failed: ${err.message}`;
    } finally { el('compare-run').disabled = false; }
  });
}
