'use strict';
// The extension as users install it: `vsce package` (@vscode/vsce, pinned) builds the
// .vsix, which is unpacked here and checked: the manifest, the grammar and the code are
// in it, the tests and the development packages are not, and every package the code
// needs at run time resolves inside it (VS Code installs no dependency of its own).
// VS Code itself is not started: its binary is not on the registries CI reaches.
const assert = require('assert');
const { execFileSync } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');
const test = require('node:test');
const { ROOT } = require('./lib/tokenize');
const { unzip } = require('./lib/unzip');

test('vsce packages a .vsix that holds the extension and what it needs', () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'aviary-vsix-'));
  try {
    const vsix = path.join(dir, 'aviary.vsix');
    const vsce = path.join(path.dirname(require.resolve('@vscode/vsce/package.json')), 'vsce');
    execFileSync(process.execPath, [vsce, 'package', '--allow-missing-repository', '--out', vsix], {
      cwd: ROOT,
      stdio: ['ignore', 'pipe', 'pipe'],
    });
    const files = unzip(fs.readFileSync(vsix));
    const root = path.join(dir, 'unpacked');
    for (const [name, data] of files) {
      fs.mkdirSync(path.dirname(path.join(root, name)), { recursive: true });
      fs.writeFileSync(path.join(root, name), data);
    }
    const ext = path.join(root, 'extension');

    const manifest = JSON.parse(fs.readFileSync(path.join(ext, 'package.json'), 'utf8'));
    const ours = JSON.parse(fs.readFileSync(path.join(ROOT, 'package.json'), 'utf8'));
    assert.strictEqual(`${manifest.publisher}.${manifest.name}`, 'aviary.aviary');
    assert.deepStrictEqual(manifest.contributes, ours.contributes);
    for (const file of ['extension.js', 'server.js', 'language-configuration.json', 'LICENSE.txt']) {
      assert.ok(files.has(`extension/${file}`), `${file} is missing from the .vsix`);
    }
    const grammar = ours.contributes.grammars[0].path;
    assert.deepStrictEqual(
      fs.readFileSync(path.join(ext, grammar), 'utf8'),
      fs.readFileSync(path.join(ROOT, grammar), 'utf8'),
    );
    const names = [...files.keys()];
    assert.deepStrictEqual(names.filter((n) => n.startsWith('extension/test/')), []);
    for (const dev of Object.keys(ours.devDependencies)) {
      assert.ok(!names.some((n) => n.startsWith(`extension/node_modules/${dev}/`)), `${dev} is in the .vsix`);
    }

    // What extension.js requires, and then what each package in the .vsix depends on.
    const inside = (from, request) => {
      const found = require.resolve(request, { paths: [from] });
      assert.ok(found.startsWith(ext + path.sep), `${request} from ${from} resolves outside: ${found}`);
    };
    inside(ext, './server');
    inside(ext, 'vscode-languageclient/node');
    const packages = names.filter((n) => /^extension\/(.*\/)?node_modules\/(@[^/]+\/)?[^/@]+\/package\.json$/.test(n));
    assert.ok(packages.length >= 3, `only ${packages.length} packages in the .vsix`);
    for (const name of packages) {
      const dir = path.dirname(path.join(root, name));
      const pkg = JSON.parse(fs.readFileSync(path.join(root, name), 'utf8'));
      for (const dep of Object.keys(pkg.dependencies || {})) {
        // Node's search: node_modules/DEP in the package's folder or a folder above it,
        // up to the extension's own.
        let found = false;
        for (let d = dir; !found && d.startsWith(ext); d = path.dirname(d)) {
          found = fs.existsSync(path.join(d, 'node_modules', dep, 'package.json'));
        }
        assert.ok(found, `${dep}, which ${pkg.name} depends on, is not in the .vsix`);
      }
    }
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
});
