// The access token's handling in the page (src/view/assets/token.mjs): the address bar loses
// the token and keeps the rest; a refused request says to open the URL `raywave view` printed.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { api, errorMessage, urlWithoutToken } from '../../src/view/assets/token.mjs';

test('urlWithoutToken drops the token and keeps the other parameters, their order and the fragment', () => {
  const cases = [
    ['http://127.0.0.1:8080/?token=ab12', 'http://127.0.0.1:8080/'],
    ['http://127.0.0.1:8080/?token=ab12#tree', 'http://127.0.0.1:8080/#tree'],
    ['http://127.0.0.1:8080/?a=1&token=ab12&b=x%20y#h', 'http://127.0.0.1:8080/?a=1&b=x%20y#h'],
    ['http://127.0.0.1:8080/?token=ab12&a=1', 'http://127.0.0.1:8080/?a=1'],
    ['http://127.0.0.1:8080/?a=1&token=', 'http://127.0.0.1:8080/?a=1'],
    ['http://127.0.0.1:8080/?token=1&token=2&q=a+b', 'http://127.0.0.1:8080/?q=a+b'],
    // An encoded name is still the token.
    ['http://127.0.0.1:8080/?t%6Fken=ab12&a', 'http://127.0.0.1:8080/?a'],
    // Names that only look like it stay.
    ['http://127.0.0.1:8080/?tokens=1&xtoken=2&a=token', 'http://127.0.0.1:8080/?tokens=1&xtoken=2&a=token'],
    ['http://localhost:9/page?x=1#token=3', 'http://localhost:9/page?x=1#token=3'],
  ];
  for (const [href, expected] of cases) assert.equal(urlWithoutToken(href), expected, href);
  // Without a query the address is left as it is.
  assert.equal(urlWithoutToken('http://127.0.0.1:8080/#a'), 'http://127.0.0.1:8080/#a');
});

test('a 403 says to open the printed URL with its token; other errors give the server\'s message', () => {
  const m = errorMessage(403, { error: 'no access token', status: 403 }, '');
  assert.match(m, /403: no access token/);
  assert.match(m, /open the URL that `raywave view` printed, with its \?token=/);
  assert.match(errorMessage(403, null, 'Forbidden'), /raywave view/);
  assert.equal(errorMessage(400, { error: 'width must be in 1..=2048, found 0', status: 400 }, ''), 'width must be in 1..=2048, found 0');
  assert.equal(errorMessage(502, null, 'Bad Gateway'), '502 Bad Gateway');
});

const reply = (status, text) => async () => ({ ok: status >= 200 && status < 300, status, text: async () => text });

test('api answers the JSON, and throws the message and the status on a refusal', async () => {
  assert.deepEqual(await api('/api/scene', {}, reply(200, '{"a": 1}')), { a: 1 });
  await assert.rejects(api('/api/scene', {}, reply(403, '{"error": "no token", "status": 403}')), e => {
    assert.equal(e.status, 403);
    assert.match(e.message, /raywave view/);
    return true;
  });
  await assert.rejects(api('/api/render', {}, reply(429, '{"error": "too many renders", "status": 429}')), /^Error: too many renders$/);
});
