#!/usr/bin/env bash
# Rebuilds three.min.js: three.js (r187, MIT licence) and its OrbitControls, the parts that
# entry.js names, as one minified script defining the global THREE. Needs Node.js and npm;
# not part of the build or the tests (the result is committed).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d)"
cp "$here/entry.js" "$work/"
cd "$work"
npm init -y > /dev/null
npm install --silent three@0.187.0 esbuild@0.25
{
  echo "/* three.js r187 (https://threejs.org), MIT licence, Copyright 2010-2025 three.js authors; bundled by assets/view/build.sh */"
  npx esbuild entry.js --bundle --minify --format=iife --global-name=THREE --log-level=warning
} > "$here/three.min.js"
rm -rf "$work"
