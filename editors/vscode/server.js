'use strict';
// How the extension starts the language server: `aviary lsp [--use-root DIR]...`
// (docs/EDITORS.md). Kept apart from extension.js, which needs VS Code, so that
// `npm test` can check it under plain Node.
const path = require('path');

/**
 * The server's command line from the `aviary.server` settings.
 * @param {{path?: string, useRoots?: string[]}} settings
 * @param {string | undefined} folder the first workspace folder, if one is open
 */
function serverCommand(settings, folder) {
  const args = ['lsp'];
  for (const root of settings.useRoots || []) {
    // A relative folder means one of the workspace, not of wherever VS Code was started.
    const dir = folder && !path.isAbsolute(root) ? path.resolve(folder, root) : root;
    args.push('--use-root', dir);
  }
  return { command: settings.path || 'aviary', args };
}

module.exports = { serverCommand };
