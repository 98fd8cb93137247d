'use strict';
// Each fixture tokenized by the grammar, line by line, against its committed snapshot
// (test/snapshots/NAME.snap). UPDATE_SNAPSHOTS=1 writes the snapshots instead; read the
// diff before committing it.
const assert = require('assert');
const fs = require('fs');
const path = require('path');
const test = require('node:test');
const { ROOT, snapshot } = require('./lib/tokenize');

const REPO = path.join(ROOT, '..', '..');
const FIXTURES = [
  path.join(REPO, 'examples', 'search_and_rescue.mission'),
  path.join(REPO, 'std', 'standard.mission'),
  ...fs
    .readdirSync(path.join(__dirname, 'fixtures'))
    .filter((name) => name.endsWith('.mission'))
    .map((name) => path.join(__dirname, 'fixtures', name)),
];
const UPDATE = process.env.UPDATE_SNAPSHOTS === '1';

for (const file of FIXTURES) {
  const name = path.basename(file, '.mission');
  test(`tokens of ${path.relative(REPO, file)}`, async () => {
    const actual = await snapshot(fs.readFileSync(file, 'utf8'));
    const snap = path.join(__dirname, 'snapshots', `${name}.snap`);
    if (UPDATE) {
      fs.writeFileSync(snap, actual);
      return;
    }
    assert.ok(fs.existsSync(snap), `no snapshot ${snap}: run with UPDATE_SNAPSHOTS=1`);
    // Line by line, so that a failure names the first source line whose tokens changed.
    const expected = fs.readFileSync(snap, 'utf8');
    const [a, e] = [actual.split('\n'), expected.split('\n')];
    for (let i = 0; i < Math.max(a.length, e.length); i++) {
      if (a[i] !== e[i]) {
        const source = e.slice(0, i + 1).findLast((l) => l.startsWith('> ')) ?? '(start)';
        assert.fail(
          `${name}.snap line ${i + 1}, under ${JSON.stringify(source)}:\n` +
            `  expected ${JSON.stringify(e[i])}\n  actual   ${JSON.stringify(a[i])}\n` +
            'run with UPDATE_SNAPSHOTS=1 if the change is meant',
        );
      }
    }
  });
}

test('every snapshot belongs to a fixture', () => {
  const names = new Set(FIXTURES.map((file) => `${path.basename(file, '.mission')}.snap`));
  assert.strictEqual(names.size, FIXTURES.length, 'two fixtures of one name');
  const stale = fs.readdirSync(path.join(__dirname, 'snapshots')).filter((n) => !names.has(n));
  assert.deepStrictEqual(stale, [], 'snapshots of no fixture: delete them');
});
