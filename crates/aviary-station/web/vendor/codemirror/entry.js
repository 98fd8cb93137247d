// What the station's editor (web/js/editor.js, web/js/lsp.js) takes from CodeMirror 6
// and its language-server client: `npm run bundle` makes codemirror.bundle.js of it, one
// ES module.
export { minimalSetup } from "codemirror";
export { EditorState, Compartment } from "@codemirror/state";
export { EditorView, lineNumbers, highlightActiveLine, highlightActiveLineGutter } from "@codemirror/view";
export { lintGutter, setDiagnostics } from "@codemirror/lint";
export { LSPClient, languageServerExtensions } from "@codemirror/lsp-client";
