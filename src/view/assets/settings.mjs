// The settings form → the settings JSON of POST /api/render (docs/VIEWER.md, "Settings JSON"),
// checked here first with the server's ranges (src/view/request.rs), so that a slip in the
// form is a message next to it rather than a request the server refuses. The server checks
// again, and alone knows each sampler's own limits. No DOM here.

/** Whole-number fields and their inclusive ranges. */
export const RANGES = {
  width: [1, 2048], height: [1, 2048], bounces: [0, 64], shadow_samples: [1, 4096], aa: [1, 64],
  seed: [0, 4294967295],
};
/** The most camera samples (width × height × aa) one render may take. */
export const MAX_CAMERA_SAMPLES = 4 * 1024 * 1024;
/** Fields with fixed choices; the samplers and engines come from GET /api/scene. */
export const CHOICES = {
  shadows: ['off', 'hard', 'soft'], light_model: ['lab', 'rpi'],
  cost_map: ['off', 'camera', 'shadow', 'reflection', 'all'], cost_measure: ['nodes', 'tests'],
};

/** `values` (field name → the form's text) as settings: `{settings, errors}`, `errors` a list
 * of `{field, message}` (empty when the settings can be sent). `choices` adds the menus the
 * server lists (`sampler`, `engine`); a field missing from `values` is left out (the server
 * keeps its own). */
export function validate(values, choices = {}) {
  const settings = {}, errors = [];
  const menus = { ...CHOICES, ...choices };
  for (const [field, [lo, hi]] of Object.entries(RANGES)) {
    if (!(field in values)) continue;
    const text = String(values[field]).trim();
    if (!/^[+-]?\d+$/.test(text)) {
      const found = text === '' ? 'nothing' : `"${text}"`;
      errors.push({ field, message: `${field}: expected a whole number in ${lo}..=${hi}, found ${found}` });
      continue;
    }
    const v = Number(text);
    if (v < lo || v > hi) errors.push({ field, message: `${field} must be in ${lo}..=${hi}, found ${v}` });
    else settings[field] = v;
  }
  for (const [field, names] of Object.entries(menus)) {
    if (!(field in values)) continue;
    const v = String(values[field]);
    if (names.includes(v)) settings[field] = v;
    else errors.push({ field, message: `${field}: expected one of ${names.join(', ')}, found "${v}"` });
  }
  const { width, height, aa } = settings;
  if (width !== undefined && height !== undefined && aa !== undefined && width * height * aa > MAX_CAMERA_SAMPLES) {
    errors.push({
      field: 'width',
      message: `width × height × aa = ${width * height * aa} camera samples: the viewer renders at most ${MAX_CAMERA_SAMPLES}`,
    });
  }
  if (settings.cost_map && settings.cost_map !== 'off' && settings.engine === 'reference') {
    errors.push({
      field: 'cost_map',
      message: "cost_map counts the wavefront engine's traversal: expected engine wavefront, or cost_map off",
    });
  }
  return { settings, errors };
}
