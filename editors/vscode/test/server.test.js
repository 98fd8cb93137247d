'use strict';
// The command line the extension starts the language server with (server.js).
const assert = require('assert');
const test = require('node:test');
const { serverCommand } = require('../server');

test('the defaults start `aviary lsp`', () => {
  assert.deepStrictEqual(serverCommand({}, undefined), { command: 'aviary', args: ['lsp'] });
});

test('aviary.server.path and each of aviary.server.useRoots, relative to the workspace', () => {
  const settings = { path: '/opt/aviary/bin/aviary', useRoots: ['lib', '/srv/shared'] };
  assert.deepStrictEqual(serverCommand(settings, '/home/pilot/site'), {
    command: '/opt/aviary/bin/aviary',
    args: ['lsp', '--use-root', '/home/pilot/site/lib', '--use-root', '/srv/shared'],
  });
  // With no folder open, a relative root is passed as written.
  assert.deepStrictEqual(serverCommand({ useRoots: ['lib'] }, undefined).args, ['lsp', '--use-root', 'lib']);
});
