#!/usr/bin/env bash
# Grammar tests for syntaxes/mod.tmLanguage.json: runs vscode-tmgrammar-test (pinned in
# package-lock.json) over tests/*.mod, or over the test files given as arguments.
# Needs node >= 18 and npm; installs into editors/vscode/node_modules (git-ignored) from the
# npm registry on first use (npm ci), then reuses it. Exit status 0 when every assertion holds.
set -euo pipefail
cd "$(dirname "$0")"

stamp=node_modules/.modc-package-lock.json
if [ ! -x node_modules/.bin/vscode-tmgrammar-test ] || [ ! -x node_modules/.bin/vsce ] || ! cmp -s package-lock.json "$stamp"; then
    npm ci --no-audit --no-fund --loglevel=error
    cp package-lock.json "$stamp"
fi

# --config package.json: the grammar is loaded the way VS Code loads it (contributes.grammars).
if [ "$#" -eq 0 ]; then set -- "tests/*.mod"; fi
exec node_modules/.bin/vscode-tmgrammar-test --config package.json "$@"
