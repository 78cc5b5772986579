// The settings form's check (src/view/assets/settings.mjs) against the ranges docs/VIEWER.md
// ("Settings JSON") gives, which src/view/request.rs enforces on the server.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { MAX_CAMERA_SAMPLES, validate } from '../../src/view/assets/settings.mjs';

const CHOICES = { sampler: ['random', 'stratified', 'sobol', 'lab'], engine: ['wavefront', 'reference'] };
const FORM = {
  width: '64', height: '48', bounces: '2', shadows: 'soft', shadow_samples: '16', sampler: 'stratified',
  light_model: 'lab', engine: 'wavefront', aa: '1', seed: '7',
};

test('a good form becomes the settings JSON, numbers as numbers', () => {
  const { settings, errors } = validate(FORM, CHOICES);
  assert.deepEqual(errors, []);
  assert.deepEqual(settings, {
    width: 64, height: 48, bounces: 2, shadows: 'soft', shadow_samples: 16, sampler: 'stratified',
    light_model: 'lab', engine: 'wavefront', aa: 1, seed: 7,
  });
});

test('the ends of every range are accepted, one past them refused with the field and range', () => {
  const ranges = { width: [1, 2048], height: [1, 2048], bounces: [0, 64], shadow_samples: [1, 4096], aa: [1, 64], seed: [0, 4294967295] };
  for (const [field, [lo, hi]] of Object.entries(ranges)) {
    // Keep width × height × aa small, so that only the field under test can fail.
    const base = { ...FORM, width: '1', height: '1', aa: '1' };
    for (const ok of [lo, hi]) {
      const { errors, settings } = validate({ ...base, [field]: String(ok) }, CHOICES);
      assert.deepEqual(errors, [], `${field} = ${ok}`);
      assert.equal(settings[field], ok);
    }
    for (const bad of [lo - 1, hi + 1]) {
      const { errors, settings } = validate({ ...base, [field]: String(bad) }, CHOICES);
      assert.deepEqual(errors, [{ field, message: `${field} must be in ${lo}..=${hi}, found ${bad}` }]);
      assert.equal(field in settings, false, 'a bad field is not sent');
    }
  }
});

test('text that is not a whole number is refused, saying what was found', () => {
  for (const [text, found] of [['', 'nothing'], ['  ', 'nothing'], ['1.5', '"1.5"'], ['abc', '"abc"'], ['1e3', '"1e3"'], ['0x10', '"0x10"']]) {
    const { errors } = validate({ ...FORM, bounces: text }, CHOICES);
    assert.deepEqual(errors, [{ field: 'bounces', message: `bounces: expected a whole number in 0..=64, found ${found}` }], text);
  }
  assert.deepEqual(validate({ ...FORM, bounces: ' 3 ' }, CHOICES).settings.bounces, 3);
});

test('menus take only their choices', () => {
  const { errors } = validate({ ...FORM, shadows: 'soft-ish', sampler: 'best' }, CHOICES);
  assert.deepEqual(errors.map(e => e.field), ['shadows', 'sampler']);
  assert.equal(errors[1].message, 'sampler: expected one of random, stratified, sobol, lab, found "best"');
});

test('more camera samples than the viewer renders are refused', () => {
  assert.equal(MAX_CAMERA_SAMPLES, 4194304);
  // Exactly the most, and one row more.
  assert.deepEqual(validate({ ...FORM, width: '2048', height: '1024', aa: '2' }, CHOICES).errors, []);
  const { errors } = validate({ ...FORM, width: '2048', height: '1025', aa: '2' }, CHOICES);
  assert.equal(errors.length, 1);
  assert.match(errors[0].message, /width × height × aa = 4198400 camera samples: the viewer renders at most 4194304/);
});

test('fields the form does not have are left out, for the server to fill', () => {
  assert.deepEqual(validate({ width: '10' }, CHOICES), { settings: { width: 10 }, errors: [] });
});

test('the cost-map overlay takes its menus, and only with the wavefront engine', () => {
  const on = { ...FORM, cost_map: 'shadow', cost_measure: 'tests' };
  assert.deepEqual(validate(on, CHOICES).errors, []);
  assert.equal(validate(on, CHOICES).settings.cost_map, 'shadow');
  assert.deepEqual(validate({ ...on, cost_map: 'sideways' }, CHOICES).errors.map(e => e.field), ['cost_map']);
  assert.deepEqual(validate({ ...on, cost_measure: 'both' }, CHOICES).errors.map(e => e.field), ['cost_measure']);
  const reference = validate({ ...on, engine: 'reference' }, CHOICES).errors;
  assert.deepEqual(reference.map(e => e.field), ['cost_map']);
  assert.match(reference[0].message, /wavefront engine's traversal/);
  assert.deepEqual(validate({ ...on, cost_map: 'off', engine: 'reference' }, CHOICES).errors, []);
});
