// The editor's language server: `aviary lsp`'s, served by the station at `/api/lsp` (a
// WebSocket carrying the token as the subprotocol `aviary.bearer.TOKEN`, one JSON-RPC
// message a frame), spoken to by @codemirror/lsp-client. Files are named by their
// absolute path on the station's machine (`file://` + the folder + the file's path), so
// that the world beside a mission and the files it USEs are found as `aviary check`
// finds them.

import { LSPClient, languageServerExtensions } from "../vendor/codemirror/codemirror.bundle.js";
import * as api from "./api.js";

export class LanguageServer {
  /// `about`: the station's `/api/station` answer. `status`: the button that tells the
  /// server's state (a click asks for the token, or connects again). `changed`: called
  /// when the server comes or goes.
  constructor(about, status, changed) {
    this.offered = !!(about && about.lsp && about.folder);
    this.folder = (about && about.folder) || "";
    this.status = status;
    this.changed = changed;
    this.client = null;
    this.socket = null;
    // The token the station last refused: not tried again until the operator asks.
    this.refused = null;
    this.state = "off";
    if (status) {
      status.hidden = !this.offered;
      // No token, or one the station refused (it restarted with a new one): asked for.
      status.onclick = async () => {
        if ((!api.token() || this.state === "refused") && !(await api.askToken())) return;
        this.connect(true);
      };
    }
    this.say("off", "language server: not connected");
  }

  /// The URI of a file of the folder (`path` relative to it, `/`-separated).
  uri(path) {
    const full = path ? `${this.folder.replace(/\/$/, "")}/${path}` : this.folder;
    return "file://" + full.split("/").map(encodeURIComponent).join("/");
  }

  /// Whether the server has the file at `path` open (and marks its diagnostics).
  serves(path) {
    return !!(this.client && path);
  }

  /// The editor extension that opens the file at `path` on the server: none without one.
  plugin(path, which) {
    if (!this.client || !path) return [];
    return this.client.plugin(this.uri(path), which === "world" ? "toml" : "aviary");
  }

  say(state, text) {
    this.state = state;
    if (!this.status) return;
    this.status.textContent = text;
    this.status.dataset.state = state;
  }

  /// Opens the socket, unless it is open or opening, or there is no server or token;
  /// a token the station refused is tried again only when `asked` (the note clicked).
  connect(asked = false) {
    if (!this.offered || this.client || this.socket) return;
    const token = api.token();
    if (!token) {
      this.say("off", "language server: give the token (click)");
      return;
    }
    if (token === this.refused && !asked) return;
    const scheme = location.protocol === "https:" ? "wss:" : "ws:";
    const socket = new WebSocket(`${scheme}//${location.host}/api/lsp`, ["aviary", "aviary.bearer." + token]);
    this.socket = socket;
    this.say("connecting", "language server: connecting");
    let handlers = [];
    socket.onmessage = (m) => {
      for (const h of handlers) h(String(m.data));
    };
    socket.onopen = () => {
      this.refused = null;
      const transport = {
        send(message) {
          if (socket.readyState !== WebSocket.OPEN) throw new Error("the language server's socket is closed");
          socket.send(message);
        },
        subscribe(h) { handlers.push(h); },
        unsubscribe(h) { handlers = handlers.filter((x) => x !== h); },
      };
      const client = new LSPClient({
        rootUri: this.uri(""),
        extensions: languageServerExtensions(),
        sanitizeHTML: sanitize,
        timeout: 10000,
      });
      this.client = client.connect(transport);
      client.initializing.then(
        () => { if (this.client === client) this.say("on", "language server: on"); },
        (e) => console.warn("the language server did not start", e),
      );
      this.changed();
    };
    socket.onclose = () => {
      const was = this.client;
      this.socket = null;
      this.client = null;
      if (was) {
        was.disconnect();
        this.changed();
        this.say("off", "language server: disconnected (click to connect)");
      } else {
        // Never opened: a wrong token, too many editors, or no station.
        this.refused = token;
        this.say("refused", "language server: refused (click to give the token)");
      }
    };
  }
}

// What of the server's Markdown (hover, completion documentation) reaches the page: the
// text, in these elements only, without attributes but a class and a web link's address.
const ALLOWED = new Set(["P", "PRE", "CODE", "EM", "STRONG", "B", "I", "DEL", "UL", "OL", "LI", "BR", "HR",
  "BLOCKQUOTE", "H1", "H2", "H3", "H4", "H5", "H6", "SPAN", "DIV", "TABLE", "THEAD", "TBODY", "TR", "TH", "TD", "A"]);

export function sanitize(html) {
  const doc = new DOMParser().parseFromString(`<!doctype html><body>${html}`, "text/html");
  clean(doc.body);
  return doc.body.innerHTML;
}

function clean(node) {
  for (const child of [...node.children]) {
    if (!ALLOWED.has(child.tagName)) {
      child.replaceWith(child.ownerDocument.createTextNode(child.textContent));
      continue;
    }
    for (const a of [...child.attributes]) {
      const link = child.tagName === "A" && a.name === "href" && /^https?:\/\//i.test(a.value);
      if (!link && a.name !== "class") child.removeAttribute(a.name);
    }
    clean(child);
  }
}
