// Debouncing: a burst of calls becomes one call, `ms` after the last, with the last call's
// arguments (the orbit re-render waits for the hand to stop). No DOM here.

/** `fn` debounced by `ms` milliseconds; `.cancel()` drops a pending call, `.pending()` says
 * whether one waits. `timers` ({setTimeout, clearTimeout}) is for the tests. */
export function debounce(fn, ms, timers = globalThis) {
  let id = null;
  const debounced = (...args) => {
    if (id !== null) timers.clearTimeout(id);
    id = timers.setTimeout(() => { id = null; fn(...args); }, ms);
  };
  debounced.cancel = () => { if (id !== null) timers.clearTimeout(id); id = null; };
  debounced.pending = () => id !== null;
  return debounced;
}
