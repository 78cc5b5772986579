// One pixel's ray tree (raywave::trace's RayTree, docs/TRACE.md) as the page shows it: a table
// row per segment, a title with the sum and the engines' check, and the lines the 3D view
// draws. No DOM here.

/** The style of a segment: its kind, or for a shadow ray whether the light was seen,
 * blocked or not tested (shadows off). Also the class of its table row and its colour's key. */
export function style(seg) {
  if (seg.kind !== 'shadow') return seg.kind;
  const blocked = seg.shadow ? seg.shadow.blocked : null;
  return blocked === null || blocked === undefined ? 'shadow_untested' : blocked ? 'shadow_blocked' : 'shadow_visible';
}

/** What a segment did, in words. */
export function outcome(s) {
  if (s.kind === 'shadow') {
    const sh = s.shadow || {};
    if (sh.blocked === null || sh.blocked === undefined) return `light ${sh.light}: not tested (shadows off)`;
    if (!sh.blocked) return `light ${sh.light}: seen`;
    const b = sh.blocker;
    return `light ${sh.light}: blocked` + (b ? ` by ${b.primitive.shape} ${b.primitive.index} at t = ${b.t.toPrecision(4)}` : '');
  }
  if (!s.hit) return 'missed: background';
  const p = s.hit.primitive;
  return `hit ${p.shape} ${p.index}` + (p.face !== null && p.face !== undefined ? ` (face ${p.face})` : '') + ` at t = ${s.hit.t.toPrecision(4)}`;
}

const rgb = v => v.map(x => x.toFixed(5)).join(' ');

/** The table: one row per segment, `cells` in the order of the table's columns (id, parent,
 * kind, depth, outcome, contribution), `className` its style. */
export const rows = tree => tree.segments.map(s => ({
  className: style(s),
  cells: [String(s.id), s.parent === null || s.parent === undefined ? '' : String(s.parent), s.kind,
    String(s.depth), outcome(s), rgb(s.contribution)],
}));

/** The title line: the pixel, the segment count, the contributions' sum and the check. */
export function title(tree) {
  const c = tree.check;
  const check = !c ? '' : c.agrees ? ', equal to both engines\' render of it' :
    `, NOT equal to the engines' render (reference ${rgb(c.reference)}, wavefront ${rgb(c.wavefront)})`;
  return `pixel (${tree.pixel.x}, ${tree.pixel.y}): ${tree.segments.length} segments, ` +
    `contributions sum to ${rgb(tree.sum)}${check}`;
}

/** Dashes of a blocked shadow ray past its blocker. */
export const DASHES = 8;

/** The 3D view's lines, {a, b, c}: each segment from its origin to its end in its style's
 * colour (`colours`, keyed by style); a blocked shadow ray solid up to its blocker and dashed
 * beyond it. */
export function lines(segments, colours) {
  const out = [];
  for (const seg of segments) {
    const st = style(seg), c = colours[st] || [1, 1, 1];
    if (st !== 'shadow_blocked') { out.push({ a: seg.origin, b: seg.end, c }); continue; }
    const blocker = seg.shadow.blocker ? seg.shadow.blocker.point : seg.origin;
    out.push({ a: seg.origin, b: blocker, c });
    const at = t => blocker.map((v, k) => v + (seg.end[k] - v) * t);
    for (let k = 0; k < DASHES; k++) out.push({ a: at(2 * k / (2 * DASHES)), b: at((2 * k + 1) / (2 * DASHES)), c });
  }
  return out;
}
