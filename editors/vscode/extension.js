// VS Code client for the modc language server: runs `modc lsp` (settings modc.path and
// modc.args) on stdio for .mod files. Plain JavaScript, no build step. Highlighting comes from
// syntaxes/mod.tmLanguage.json and works even if the server cannot be started.
"use strict";

const path = require("path");
const vscode = require("vscode");

let client = null;
let output = null;

function expand(value, folder) {
  // VS Code does not substitute variables in settings: support the two useful ones here.
  const home = process.env.HOME || process.env.USERPROFILE || "";
  let s = String(value || "");
  if (folder) {
    s = s.split("${workspaceFolder}").join(folder.uri.fsPath);
  }
  s = s.split("${userHome}").join(home);
  if (s.startsWith("~/")) {
    s = path.join(home, s.slice(2));
  }
  return s;
}

function serverCommand() {
  const config = vscode.workspace.getConfiguration("modc");
  const folder = (vscode.workspace.workspaceFolders || [])[0];
  const command = expand(config.get("path", "modc"), folder) || "modc";
  const args = (config.get("args", ["lsp"]) || ["lsp"]).map((a) => expand(a, folder));
  return { command, args };
}

async function start(context) {
  let lc;
  try {
    lc = require("vscode-languageclient/node");
  } catch (err) {
    vscode.window.showWarningMessage(
      "modc: vscode-languageclient is not installed (run `npm install` in editors/vscode); " +
        "highlighting works, diagnostics and completion need the language server."
    );
    return;
  }
  const { command, args } = serverCommand();
  const serverOptions = {
    run: { command, args, transport: lc.TransportKind.stdio },
    debug: { command, args, transport: lc.TransportKind.stdio },
  };
  const clientOptions = {
    documentSelector: [
      { scheme: "file", language: "mod" },
      { scheme: "untitled", language: "mod" },
    ],
    outputChannel: output,
  };
  client = new lc.LanguageClient("modc", "modc language server", serverOptions, clientOptions);
  try {
    await client.start();
  } catch (err) {
    client = null;
    const choice = await vscode.window.showErrorMessage(
      `modc: could not start \`${[command].concat(args).join(" ")}\` (${err && err.message ? err.message : err}). ` +
        "Install modc from its checkout (pip install -e PATH) or set `modc.path` to its executable.",
      "Open Settings"
    );
    if (choice === "Open Settings") {
      vscode.commands.executeCommand("workbench.action.openSettings", "modc.path");
    }
  }
}

async function stop() {
  if (client) {
    const c = client;
    client = null;
    try {
      await c.stop();
    } catch (err) {
      // the server may already be gone
    }
  }
}

async function restart(context) {
  await stop();
  await start(context);
}

function activate(context) {
  output = vscode.window.createOutputChannel("modc");
  context.subscriptions.push(output);
  context.subscriptions.push(
    vscode.commands.registerCommand("modc.restartServer", () => restart(context))
  );
  context.subscriptions.push(
    vscode.workspace.onDidChangeConfiguration((e) => {
      if (e.affectsConfiguration("modc.path") || e.affectsConfiguration("modc.args")) {
        restart(context);
      }
    })
  );
  return start(context);
}

function deactivate() {
  return stop();
}

module.exports = { activate, deactivate };
