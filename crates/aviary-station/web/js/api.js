// Calls to the station and the operator API. The token is asked for once and kept for
// this browser session only (sessionStorage): never in the URL, never in localStorage.

const KEY = "aviary.token";

export function token() {
  return sessionStorage.getItem(KEY) || "";
}

export function setToken(value) {
  if (value) sessionStorage.setItem(KEY, value.trim());
  else sessionStorage.removeItem(KEY);
}

/// Asks the operator for the token; resolves to whether one was given.
export function askToken() {
  const dialog = document.getElementById("token-dialog");
  const input = document.getElementById("token-input");
  input.value = token();
  return new Promise((resolve) => {
    dialog.onclose = () => {
      if (dialog.returnValue === "ok" && input.value.trim()) {
        setToken(input.value);
        resolve(true);
      } else resolve(false);
    };
    dialog.showModal();
  });
}

/// A GET whose answer is not JSON (a trace, a report): the response itself, with the
/// token when one is known; on 401 asks for it once and tries again.
export async function raw(path) {
  const get = () => fetch(path, { headers: token() ? { Authorization: "Bearer " + token() } : {} });
  let response = await get();
  if (response.status === 401 && (await askToken())) response = await get();
  return response;
}

/// A JSON call. Resolves to `{ok, status, body}`; on 401 asks for the token once and
/// tries again.
export async function call(method, path, body, retried = false) {
  const headers = {};
  if (token()) headers["Authorization"] = "Bearer " + token();
  if (body !== undefined) headers["Content-Type"] = "application/json";
  let response;
  try {
    response = await fetch(path, {
      method,
      headers,
      body: body === undefined ? undefined : JSON.stringify(body),
    });
  } catch (e) {
    return { ok: false, status: 0, body: { error: "the station cannot be reached: is it still running?" } };
  }
  let parsed = null;
  try {
    parsed = await response.json();
  } catch (e) {
    parsed = { error: `the station answered ${response.status} without JSON` };
  }
  if (response.status === 401 && !retried && (await askToken())) {
    return call(method, path, body, true);
  }
  return { ok: response.ok, status: response.status, body: parsed };
}

/// The event stream from the mission's start (telemetry from now on): every trace event,
/// as the trace file has it. `onEvent` gets
/// each; `onClose` when the stream ends.
export function events(onEvent, onClose, onNote) {
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  const protocols = ["aviary"];
  if (token()) protocols.push("aviary.bearer." + token());
  // Batches every 100 ms: the window's events and each drone's latest telemetry, so a
  // large fleet does not send more than the page can draw.
  const socket = new WebSocket(`${scheme}//${location.host}/api/events?from=start&every=100`, protocols);
  socket.onmessage = (m) => {
    let data;
    try {
      data = JSON.parse(m.data);
    } catch (e) {
      console.warn("an event that is not JSON", e);
      return;
    }
    for (const e of Array.isArray(data) ? data : [data]) {
      // Notes (`dropped`, `history_dropped`, `lagged`) are not events.
      if (e && typeof e.event === "string") onEvent(e);
      else if (e && onNote) onNote(e);
    }
  };
  socket.onclose = () => onClose && onClose();
  return socket;
}
