// The access token: `raywave view` prints http://127.0.0.1:PORT/?token=HEX, the server trades
// the token for a cookie on that first request, and every later request carries the cookie.
// The page then takes the token out of the address bar, so that it does not stay in the
// history or show in a screen share. No DOM here.

/** `href` without its `token` query parameters; every other parameter keeps its place and
 * spelling, and the fragment stays. */
export function urlWithoutToken(href) {
  const url = new URL(href);
  if (!url.search) return href;
  const name = part => {
    const raw = part.split('=')[0].replace(/\+/g, ' ');
    try { return decodeURIComponent(raw); } catch (_) { return raw; }
  };
  const kept = url.search.slice(1).split('&').filter(p => p !== '' && name(p) !== 'token');
  return `${url.origin}${url.pathname}${kept.length ? `?${kept.join('&')}` : ''}${url.hash}`;
}

/** The message for a refused request: for a 403, what to do about it (the token), else the
 * server's JSON message, or the status and body when there is none. */
export function errorMessage(status, body, text) {
  const said = body && typeof body.error === 'string' ? body.error : '';
  if (status === 403) {
    return `the server refused this page (403${said ? `: ${said}` : ''}): open the URL that \`raywave view\` ` +
      'printed, with its ?token=…, in this browser';
  }
  return said || `${status} ${text || ''}`.trim();
}

/** fetch, answering the JSON body; a refused request throws an Error with `errorMessage`'s
 * text and the status in `.status`. `fetchImpl` is for the tests. */
export async function api(path, options, fetchImpl = globalThis.fetch) {
  const r = await fetchImpl(path, options);
  const text = await r.text();
  let body = null;
  try { body = JSON.parse(text); } catch (_) { body = null; }
  if (!r.ok) throw Object.assign(new Error(errorMessage(r.status, body, text)), { status: r.status });
  return body;
}
