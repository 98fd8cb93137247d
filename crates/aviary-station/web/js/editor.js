// The mission and world editor: a text area with line numbers, and the check's
// diagnostics on their lines (a mark in the gutter, the message below, a click goes to
// the line).

export class Editor {
  constructor() {
    this.text = document.getElementById("text");
    this.gutter = document.getElementById("gutter");
    this.list = document.getElementById("diagnostics");
    this.files = { mission: { path: "", text: "" }, world: { path: "", text: "" } };
    this.showing = "mission";
    this.diagnostics = [];
    this.text.addEventListener("input", () => {
      this.files[this.showing].text = this.text.value;
      this.files[this.showing].dirty = true;
      this.numbers();
    });
    this.text.addEventListener("scroll", () => { this.gutter.scrollTop = this.text.scrollTop; });
  }

  load(which, path, text) {
    this.files[which] = { path, text, dirty: false };
    if (this.showing === which) this.show(which);
  }

  show(which) {
    this.showing = which;
    this.text.value = this.files[which].text;
    this.numbers();
  }

  /// The diagnostics of a check, each shown on its line of its file.
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
    this.numbers();
  }

  go(d) {
    const which = d.file === this.files.world.path ? "world" : "mission";
    if (which !== this.showing) {
      this.show(which);
      document.getElementById("edit-mission").classList.toggle("active", which === "mission");
      document.getElementById("edit-world").classList.toggle("active", which === "world");
    }
    const lines = this.text.value.split("\n");
    let offset = 0;
    for (let i = 0; i < d.line - 1 && i < lines.length; i++) offset += lines[i].length + 1;
    this.text.focus();
    this.text.setSelectionRange(offset + d.column - 1, offset + (d.end_line === d.line ? d.end_column - 1 : lines[d.line - 1].length));
    const lineHeight = 17;
    this.text.scrollTop = Math.max(0, (d.line - 5) * lineHeight);
  }

  numbers() {
    const path = this.files[this.showing].path;
    const marks = new Map();
    for (const d of this.diagnostics) {
      if (d.file !== path) continue;
      if (d.severity === "error" || !marks.has(d.line)) marks.set(d.line, d.severity === "error" ? "err" : "warn");
    }
    const count = this.text.value.split("\n").length;
    const fragment = document.createDocumentFragment();
    for (let i = 1; i <= count; i++) {
      const span = document.createElement("span");
      span.textContent = String(i);
      const mark = marks.get(i);
      if (mark) { span.className = mark; span.dataset.line = i; }
      fragment.append(span, "\n");
    }
    this.gutter.textContent = "";
    this.gutter.appendChild(fragment);
    this.gutter.scrollTop = this.text.scrollTop;
  }
}
