#!/usr/bin/env bash
# Packages the extension as a .vsix through the manifest's own `npm run package` (vsce, its
# client bundled by esbuild into dist/extension.js; both installed by scripts/setup.sh from
# package-lock.json) and checks that it holds what VS Code needs and nothing else (an
# allow-list: a new file in the folder fails here until it is needed or in .vscodeignore).
#   bash editor-support/vscode/scripts/package.sh [OUT.vsix]   (default: editor-support/vscode/psys.vsix)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="$(realpath -m "${1:-$here/psys.vsix}")"
cd "$here"
if [ ! -x node_modules/.bin/vsce ]; then
  echo "package.sh: node_modules/.bin/vsce is missing: run scripts/setup.sh (npm ci in editor-support/vscode)" >&2
  exit 1
fi
npm run --silent package -- --out "$out" </dev/null
# The bundle loads with only `vscode` from the host, and has the extension's entry points.
node -e '
const Module = require("module"), load = Module._load;
Module._load = function (request) {
    return request === "vscode" ? new Proxy({}, { get: () => function () {} }) : load.apply(this, arguments);
};
const extension = require(process.argv[1]);
if (typeof extension.activate !== "function" || typeof extension.deactivate !== "function")
    throw new Error("dist/extension.js has no activate and deactivate");' "$here/dist/extension.js"
python3 - "$out" <<'PY'
import sys, zipfile, json
names = set(zipfile.ZipFile(sys.argv[1]).namelist())
manifest = json.loads(zipfile.ZipFile(sys.argv[1]).read("extension/package.json"))
need = ["extension/language-configuration.json", "extension/syntaxes/psys.tmLanguage.json",
        "extension/snippets/psys.json", "extension/icons/psys.png", "extension/icons/psys-file.svg",
        "extension/images/preview.png", "extension/readme.md",
        "extension/dist/extension.js"]
missing = [n for n in need if n not in names and n.replace("readme", "README") not in names]
# Nothing else: the client is bundled (no node_modules, no sources beside the bundle), and
# no tests, scripts or the repository's dotfiles.
package = {"[Content_Types].xml", "extension.vsixmanifest", "extension/package.json"}
extra = sorted(n for n in names if n not in package and n not in need and n.replace("README", "readme") not in need)
if missing or extra:
    sys.exit(f"{sys.argv[1]}: missing {missing}; files VS Code does not need: {extra[:8]}")
print(f"{sys.argv[1]}: {len(names)} files, {manifest['name']} {manifest['version']}, everything VS Code needs")
PY
