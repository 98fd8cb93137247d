// The mission and world editor: CodeMirror 6 with line numbers, speaking to the language
// server of `aviary lsp` over the station's WebSocket (`lsp.js`): its diagnostics as you
// type (marked in the text and the gutter), completion and hover. The Check button's
// diagnostics are listed below it; a click goes to the place.

import {
  EditorState, EditorView, Compartment, minimalSetup, lineNumbers, highlightActiveLine,
  highlightActiveLineGutter, lintGutter, setDiagnostics,
} from "../vendor/codemirror/codemirror.bundle.js";
import { LanguageServer } from "./lsp.js";

const WHICH = ["mission", "world"];

export class Editor {
  /// `about` is the station's `/api/station` answer: its folder and whether it serves a
  /// language server.
  constructor(about) {
    this.list = document.getElementById("diagnostics");
    this.files = { mission: { path: "", text: "" }, world: { path: "", text: "" } };
    this.showing = "mission";
    this.diagnostics = [];
    this.server = new LanguageServer(about, document.getElementById("lsp-status"), () => this.attach());
    this.views = {};
    this.slots = {};
    const host = document.getElementById("editor");
    for (const which of WHICH) {
      const box = document.createElement("div");
      box.className = "editor-file";
      box.dataset.file = which;
      box.hidden = which !== this.showing;
      host.appendChild(box);
      this.slots[which] = new Compartment();
      this.views[which] = new EditorView({ state: this.state(which), parent: box });
    }
    // The operator starts editing: the language server is asked for then if not before
    // (the token may have been given since the page opened).
    for (const e of ["focusin", "pointerdown", "keydown"]) host.addEventListener(e, () => this.server.connect());
  }

  get view() {
    return this.views[this.showing];
  }

  state(which) {
    const f = this.files[which];
    return EditorState.create({
      doc: f.text,
      extensions: [
        minimalSetup,
        lineNumbers(),
        highlightActiveLine(),
        highlightActiveLineGutter(),
        lintGutter(),
        EditorView.contentAttributes.of({ "aria-label": `the ${which} file's text`, spellcheck: "false" }),
        EditorView.updateListener.of((u) => {
          if (!u.docChanged) return;
          this.files[which].text = u.state.doc.toString();
          this.files[which].dirty = true;
        }),
        this.slots[which].of(this.server.plugin(f.path, which)),
      ],
    });
  }

  load(which, path, text) {
    this.files[which] = { path, text, dirty: false };
    // A new state: the last file's server plugin goes (closing it there), this one's comes.
    this.views[which].setState(this.state(which));
    this.marks(which);
    this.server.connect();
  }

  show(which) {
    this.showing = which;
    for (const w of WHICH) this.views[w].dom.parentElement.hidden = w !== which;
    this.views[which].requestMeasure();
  }

  /// The language server came or went: each file is opened there (or no longer).
  attach() {
    for (const which of WHICH) {
      const plugin = this.server.plugin(this.files[which].path, which);
      this.views[which].dispatch({ effects: this.slots[which].reconfigure(plugin) });
      this.marks(which);
    }
  }

  /// The diagnostics of a check, listed under the editor and, without a language server
  /// (whose own are marked as the operator types), marked on their lines.
  mark(diagnostics) {
    this.diagnostics = diagnostics || [];
    this.list.textContent = "";
    for (const d of this.diagnostics) {
      const li = document.createElement("li");
      li.className = d.severity;
      li.textContent = d.text || `${d.file}:${d.line}:${d.column}: ${d.severity}[${d.code}]: ${d.message}\n${d.help ? "help: " + d.help : ""}`;
      li.dataset.code = d.code;
      li.dataset.line = d.line;
      li.onclick = () => this.go(d);
      this.list.appendChild(li);
    }
    for (const which of WHICH) this.marks(which);
  }

  /// The check's diagnostics marked in a file, unless the language server marks it.
  marks(which) {
    if (this.server.serves(this.files[which].path)) return;
    const view = this.views[which], path = this.files[which].path;
    const shown = this.diagnostics.filter((d) => path && d.file === path).map((d) => {
      const { from, to } = this.range(view.state.doc, d);
      return { from, to, severity: d.severity === "error" ? "error" : d.severity === "warning" ? "warning" : "info",
        message: `${d.code ? d.code + ": " : ""}${d.message || d.text || ""}` };
    });
    view.dispatch(setDiagnostics(view.state, shown));
  }

  /// Where a diagnostic (1-based line and column, `end_line`/`end_column` after it) is in
  /// `doc`, held inside it.
  range(doc, d) {
    const at = (line, column) => {
      const l = doc.line(Math.min(Math.max(1, line || 1), doc.lines));
      return l.from + Math.min(Math.max(0, (column || 1) - 1), l.length);
    };
    const from = at(d.line, d.column);
    const to = d.end_line ? at(d.end_line, d.end_column) : doc.lineAt(from).to;
    return { from, to: Math.max(from, to) };
  }

  go(d) {
    const which = d.file === this.files.world.path ? "world" : "mission";
    if (which !== this.showing) {
      this.show(which);
      document.getElementById("edit-mission").classList.toggle("active", which === "mission");
      document.getElementById("edit-world").classList.toggle("active", which === "world");
    }
    const view = this.views[which];
    const { from, to } = this.range(view.state.doc, d);
    view.dispatch({ selection: { anchor: from, head: to }, effects: EditorView.scrollIntoView(from, { y: "center" }) });
    view.focus();
  }
}
