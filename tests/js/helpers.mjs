// Shared by the page's tests: a seeded random generator (the same cases on every run) and
// near-equality of numbers and vectors.
import assert from 'node:assert/strict';

/** mulberry32: a small seeded generator of floats in [0, 1). */
export function seeded(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/** A float in [lo, hi) from `rand`. */
export const between = (rand, lo, hi) => lo + (hi - lo) * rand();

/** A point in the cube [-s, s]³ from `rand`. */
export const point = (rand, s = 1) => [between(rand, -s, s), between(rand, -s, s), between(rand, -s, s)];

/** Asserts |a − b| <= eps for numbers or arrays of numbers. */
export function near(a, b, eps = 1e-9, what = '') {
  if (Array.isArray(a)) {
    assert.equal(a.length, b.length, `${what}: lengths`);
    a.forEach((v, k) => near(v, b[k], eps, `${what}[${k}]`));
    return;
  }
  assert.ok(Math.abs(a - b) <= eps, `${what}: ${a} is not within ${eps} of ${b}`);
}

/** A fake clock for setTimeout/clearTimeout: `advance(ms)` runs what falls due, in order. */
export function fakeTimers() {
  let now = 0, next = 1;
  const pending = new Map();
  return {
    setTimeout(fn, ms) { const id = next++; pending.set(id, { fn, at: now + ms }); return id; },
    clearTimeout(id) { pending.delete(id); },
    advance(ms) {
      now += ms;
      const due = [...pending].filter(([, t]) => t.at <= now).sort((a, b) => a[1].at - b[1].at);
      for (const [id, t] of due) { pending.delete(id); t.fn(); }
    },
    get size() { return pending.size; },
  };
}
