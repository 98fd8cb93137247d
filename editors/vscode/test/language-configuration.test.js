'use strict';
// The editing rules of language-configuration.json: VS Code indents after a line that
// ends in `:` (a header: the language's blocks are its indentation), and takes `ELSE`
// back a level; a `:` in a string or a comment is no header's.
const assert = require('assert');
const fs = require('fs');
const path = require('path');
const test = require('node:test');
const { ROOT } = require('./lib/tokenize');

const config = JSON.parse(fs.readFileSync(path.join(ROOT, 'language-configuration.json'), 'utf8'));
// VS Code compiles these patterns as JavaScript regular expressions.
const increase = new RegExp(config.indentationRules.increaseIndentPattern);
const decrease = new RegExp(config.indentationRules.decreaseIndentPattern);

test('a header indents the next line, and nothing else does', () => {
  for (const line of [
    'MISSION Search:',
    '    PARALLEL FOR scouts AS d:',
    '    ON EVERY Person_Found WITH where ONE AT A TIME:  // one at a time',
    '    WAITFOR scout1.speed < 5m/s:',
    '    IF scout1.call_sign = "Eagle: One":',
    '    PERFORM:',
  ]) {
    assert.match(line, increase, line);
  }
  for (const line of [
    '    scout1 FlyTo WITH Tower',
    '        radius: 50m',
    '    // the next block:',
    '    scout1 Hover WITH 10s // then:',
    '    SIGNAL Found WITH "at:"',
    '    /* a comment: */',
  ]) {
    assert.doesNotMatch(line, increase, line);
  }
});

test('ELSE goes back a level once its header is written', () => {
  assert.match('        ELSE:', decrease);
  assert.match('        ELSE IF carrier.battery > 40%:', decrease);
  assert.doesNotMatch('        ELSE IF carrier.battery', decrease);
  assert.doesNotMatch('        ELSEWHERE Hover:', decrease);
});

test("the comments are the language's: // to the end of the line, /* */ over several", () => {
  assert.deepStrictEqual(config.comments, { lineComment: '//', blockComment: ['/*', '*/'] });
});
