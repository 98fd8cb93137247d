// Writes LICENSES.md: every package bundled into codemirror.bundle.js (the lockfile's
// packages but the dev ones, esbuild), its version, integrity and licence text as the
// package ships it. `npm run licences`, after `npm ci`.

import { readFileSync, readdirSync, writeFileSync } from "node:fs";
import { join } from "node:path";

const lock = JSON.parse(readFileSync("package-lock.json", "utf8"));
let out = "# Licences of the bundled packages\n\n" +
  "`codemirror.bundle.js` is made of these packages of the npm registry, at these versions " +
  "(from `package-lock.json`); each one's licence follows, as the package ships it.\n\n" +
  "| package | version | licence | integrity |\n| --- | --- | --- | --- |\n";
const texts = [];
for (const [path, p] of Object.entries(lock.packages)) {
  if (!path || p.dev) continue;
  const name = path.replace(/^.*node_modules\//, "");
  const file = readdirSync(path).find((f) => /^(LICENSE|LICENCE|COPYING)(\.md|\.txt)?$/i.test(f));
  if (!file) throw new Error(`${name} ships no licence file`);
  out += `| ${name} | ${p.version} | ${p.license} | ${p.integrity} |\n`;
  texts.push(`## ${name} ${p.version}\n\n\`\`\`\n${readFileSync(join(path, file), "utf8").trim()}\n\`\`\`\n`);
}
writeFileSync("LICENSES.md", out + "\n" + texts.join("\n"));
