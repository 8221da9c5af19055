#!/usr/bin/env bash
# Packages the extension as a .vsix with @vscode/vsce (installed by scripts/setup.sh from
# package-lock.json) and checks that it holds what VS Code needs.
#   bash editor-support/vscode/scripts/package.sh [OUT.vsix]   (default: editor-support/vscode/psys.vsix)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="$(realpath -m "${1:-$here/psys.vsix}")"
cd "$here"
if [ ! -x node_modules/.bin/vsce ]; then
  echo "package.sh: node_modules/.bin/vsce is missing: run scripts/setup.sh (npm ci in editor-support/vscode)" >&2
  exit 1
fi
node_modules/.bin/vsce package --skip-license --no-rewrite-relative-links --out "$out"
python3 - "$out" <<'PY'
import sys, zipfile, json
names = set(zipfile.ZipFile(sys.argv[1]).namelist())
manifest = json.loads(zipfile.ZipFile(sys.argv[1]).read("extension/package.json"))
need = ["extension/extension.js", "extension/language-configuration.json", "extension/syntaxes/psys.tmLanguage.json",
        "extension/snippets/psys.json", "extension/icons/psys.png", "extension/icons/psys-file.svg",
        "extension/images/preview.png", "extension/readme.md",
        "extension/node_modules/vscode-languageclient/node.js"]
missing = [n for n in need if n not in names and n.replace("readme", "README") not in names]
dev = [n for n in names if "/node_modules/vscode-textmate/" in n or "/node_modules/@vscode/vsce" in n or "/test/" in n]
if missing or dev:
    sys.exit(f"{sys.argv[1]}: missing {missing}; development files packaged: {dev[:5]}")
print(f"{sys.argv[1]}: {len(names)} files, {manifest['name']} {manifest['version']}, everything VS Code needs")
PY
