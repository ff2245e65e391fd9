#!/usr/bin/env bash
# Packages the extension into a .vsix with vsce (pinned in package-lock.json): the same npm ci
# as test.sh into editors/vscode/node_modules (git-ignored), then `vsce package`. Arguments go to
# vsce, e.g. `bash package.sh -o /tmp/modc.vsix`. Needs node >= 20 and npm.
set -euo pipefail
cd "$(dirname "$0")"

stamp=node_modules/.modc-package-lock.json
if [ ! -x node_modules/.bin/vsce ] || ! cmp -s package-lock.json "$stamp"; then
    npm ci --no-audit --no-fund --loglevel=error
    cp package-lock.json "$stamp"
fi
# modc has no public repository URL to name: the extension is installed from a checkout.
exec node_modules/.bin/vsce package --allow-missing-repository "$@" </dev/null
