'use strict';
// The grammar against the language's reference, docs/LANGUAGE.md: every keyword it
// lists, alone on a line, is a keyword (or TRUE and FALSE constants), and a word in other
// letters is a name; every unit of its table is a unit, glued or after a space. The
// lexer's own keyword table is held to the grammar by crates/aviary-syntax/tests/grammar.rs.
const assert = require('assert');
const fs = require('fs');
const path = require('path');
const test = require('node:test');
const { ROOT, tokenize } = require('./lib/tokenize');

const LANGUAGE = fs.readFileSync(path.join(ROOT, '..', '..', 'docs', 'LANGUAGE.md'), 'utf8');

/** The scopes of the one token of `line` that spells `word`. */
async function scopesOf(line, word) {
  const [{ tokens }] = await tokenize(line);
  const token = tokens.find((t) => t.text === word);
  assert.ok(token, `${JSON.stringify(line)} has no token ${JSON.stringify(word)}`);
  return token.scopes;
}

test('every keyword of docs/LANGUAGE.md is a keyword of the grammar', async () => {
  const list = LANGUAGE.match(/\*\*Keywords are written in capitals\*\*, exactly: `([^`]+)`/);
  assert.ok(list, 'LANGUAGE.md no longer lists the keywords where this test looks');
  const keywords = list[1].split(/\s+/);
  assert.ok(keywords.length >= 30, `only ${keywords.length} keywords read`);
  for (const word of keywords) {
    const scopes = await scopesOf(word, word);
    const last = scopes[scopes.length - 1];
    assert.match(last, /^(keyword\.|constant\.language\.)/, `${word}: ${scopes.join(' ')}`);
    // Keywords are capitals exactly: `Pause` is a name.
    const name = word[0] + word.slice(1).toLowerCase();
    assert.deepStrictEqual(await scopesOf(name, name), ['source.aviary'], name);
  }
});

test('every unit of docs/LANGUAGE.md is a unit of the grammar', async () => {
  const table = LANGUAGE.split('\n').filter((l) => /^\| (length|duration|speed|angle|ratio) \|/.test(l));
  const units = table.flatMap((row) => [...row.split('|')[2].matchAll(/`([^`]+)`/g)].map((m) => m[1]));
  assert.deepStrictEqual(units.sort(), ['%', 'deg', 'h', 'km', 'km/h', 'm', 'm/s', 'min', 's']);
  for (const unit of units) {
    // `%` only glued: `25 %` is an unknown character to the lexer.
    for (const line of unit === '%' ? [`20${unit}`] : [`20${unit}`, `20 ${unit}`]) {
      assert.deepStrictEqual(await scopesOf(line, '20'), ['source.aviary', 'constant.numeric.aviary'], line);
      assert.deepStrictEqual(await scopesOf(line, unit), ['source.aviary', 'keyword.other.unit.aviary'], line);
    }
  }
});
