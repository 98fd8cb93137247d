'use strict';
// The extension's grammar, loaded as VS Code loads it: vscode-textmate on the Oniguruma
// regular expressions of vscode-oniguruma (its WebAssembly build, from node_modules).
const fs = require('fs');
const path = require('path');
const oniguruma = require('vscode-oniguruma');
const textmate = require('vscode-textmate');

const ROOT = path.join(__dirname, '..', '..');
const GRAMMAR = path.join(ROOT, 'syntaxes', 'aviary.tmLanguage.json');

let loaded;

/** The grammar of `source.aviary`, loaded once. */
function grammar() {
  loaded ??= (async () => {
    const wasm = fs.readFileSync(require.resolve('vscode-oniguruma/release/onig.wasm'));
    await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.length));
    const registry = new textmate.Registry({
      onigLib: Promise.resolve({
        createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
        createOnigString: (text) => new oniguruma.OnigString(text),
      }),
      loadGrammar: async (scopeName) =>
        scopeName === 'source.aviary'
          ? textmate.parseRawGrammar(fs.readFileSync(GRAMMAR, 'utf8'), GRAMMAR)
          : null,
    });
    return registry.loadGrammar('source.aviary');
  })();
  return loaded;
}

/** Each line of `text` with its tokens: `{ line, tokens: [{ text, scopes }] }`. */
async function tokenize(text) {
  const g = await grammar();
  let state = textmate.INITIAL;
  return text.split(/\r?\n/).map((line) => {
    const result = g.tokenizeLine(line, state);
    state = result.ruleStack;
    const tokens = result.tokens.map((t) => ({
      text: line.slice(t.startIndex, t.endIndex),
      scopes: t.scopes,
    }));
    return { line, tokens };
  });
}

/**
 * The snapshot of a file: each source line after `> `, then one line per token,
 * `  "text"  scope scope...`. Blank tokens with no scope but the file's are left out.
 */
async function snapshot(text) {
  const out = [];
  for (const { line, tokens } of await tokenize(text)) {
    out.push(`> ${line}`);
    for (const t of tokens) {
      if (t.text.trim() === '' && t.scopes.length === 1) continue;
      out.push(`  ${JSON.stringify(t.text)}  ${t.scopes.join(' ')}`);
    }
  }
  return out.join('\n') + '\n';
}

module.exports = { ROOT, tokenize, snapshot };
