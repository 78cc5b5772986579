// src/view/assets/debounce.mjs: a burst of calls is one call, after the last, with its
// arguments (the orbit re-render).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { debounce } from '../../src/view/assets/debounce.mjs';
import { fakeTimers } from './helpers.mjs';

test('a burst is one call, `ms` after the last call, with the last arguments', () => {
  const clock = fakeTimers(), calls = [];
  const d = debounce((...a) => calls.push(a), 200, clock);
  for (let k = 0; k < 10; k++) { d(k, 'x'); clock.advance(50); }
  // 50 ms after the last call: nothing yet.
  assert.deepEqual(calls, []);
  assert.equal(d.pending(), true);
  clock.advance(149);
  assert.deepEqual(calls, []);
  clock.advance(1);
  assert.deepEqual(calls, [[9, 'x']]);
  assert.equal(d.pending(), false);
  // A later call is a new burst.
  d('again');
  clock.advance(200);
  assert.deepEqual(calls, [[9, 'x'], ['again']]);
  assert.equal(clock.size, 0, 'no timer left behind');
});

test('cancel drops the pending call', () => {
  const clock = fakeTimers(), calls = [];
  const d = debounce(() => calls.push(1), 200, clock);
  d(); clock.advance(100); d.cancel();
  clock.advance(1000);
  assert.deepEqual(calls, []);
  assert.equal(d.pending(), false);
});

test('with the real timers too', async () => {
  const calls = [];
  const d = debounce(v => calls.push(v), 20);
  d(1); d(2); d(3);
  await new Promise(r => setTimeout(r, 80));
  assert.deepEqual(calls, [3]);
});
