'use strict';
// The Aviary extension: the language of `.mission` files (its grammar and editing
// rules are declared in package.json) and `aviary lsp`, the language server, started
// for them through vscode-languageclient. docs/EDITORS.md describes both.
const vscode = require('vscode');
const { LanguageClient } = require('vscode-languageclient/node');
const { serverCommand } = require('./server');

/** @type {LanguageClient | undefined} */
let client;

async function start() {
  const settings = vscode.workspace.getConfiguration('aviary.server');
  const folder = vscode.workspace.workspaceFolders?.[0]?.uri.fsPath;
  const { command, args } = serverCommand(
    { path: settings.get('path'), useRoots: settings.get('useRoots') },
    folder,
  );
  // No `transport`: the client then adds no `--stdio`, and speaks over the process's
  // stdin and stdout, which is what `aviary lsp` does.
  const server = { command, args, options: folder ? { cwd: folder } : {} };
  client = new LanguageClient('aviary', 'Aviary', server, {
    documentSelector: [{ scheme: 'file', language: 'aviary' }],
  });
  try {
    await client.start();
  } catch (err) {
    vscode.window.showErrorMessage(
      `Aviary: \`${command} ${args.join(' ')}\` did not start (${err.message}). ` +
        'Set aviary.server.path to the aviary program.',
    );
  }
}

async function stop() {
  const old = client;
  client = undefined;
  if (old) {
    await old.stop().catch(() => {});
  }
}

// Restarts one after the other: two quick changes of the settings must not start two
// servers.
let restarting = Promise.resolve();
function restart() {
  restarting = restarting.then(async () => {
    await stop();
    await start();
  });
  return restarting;
}

/** @param {vscode.ExtensionContext} context */
async function activate(context) {
  context.subscriptions.push(
    vscode.commands.registerCommand('aviary.restartServer', restart),
    vscode.workspace.onDidChangeConfiguration((event) => {
      if (event.affectsConfiguration('aviary.server')) {
        restart();
      }
    }),
  );
  await start();
}

function deactivate() {
  return stop();
}

module.exports = { activate, deactivate };
