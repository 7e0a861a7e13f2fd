#!/usr/bin/env bash
# The web viewer in a real browser: installs what it needs (Debian's Chromium, the
# viewer's npm packages), checks that the committed bundle is what viewer/src builds to,
# exports a page with the tumble binary and drives it in headless Chromium
# (viewer/test/browser.mjs). Screenshots are kept in target/browser-test/.
# Usage: scripts/browser-test.sh            (scripts/test.sh runs it)
set -euo pipefail
cd "$(dirname "$0")/.."

chromium="${CHROMIUM:-/usr/bin/chromium}"
if [ ! -x "$chromium" ]; then
    echo "installing Chromium (Debian packages chromium, fonts-dejavu-core)"
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq chromium fonts-dejavu-core >/dev/null
fi

# npm ci installs exactly package-lock.json: three, esbuild and playwright-core (which
# drives the system Chromium and downloads no browser of its own).
(cd viewer && npm ci --no-audit --no-fund --loglevel=error)

out=target/browser-test
mkdir -p "$out"
(cd viewer && node build.mjs "../$out/viewer.js")
if ! cmp -s "$out/viewer.js" viewer/dist/viewer.js; then
    echo "viewer/dist/viewer.js is stale: run 'npm run build' in viewer/ and commit it" >&2
    exit 1
fi

# The binary `cargo test` builds for the CLI's tests (test profile): after scripts/test.sh's
# test run this is a no-op, where `cargo build` would compile every crate again in the
# dev profile.
cargo test --locked -q -p tumble-cli --no-run
target/debug/tumble export-html viewer/test/falling.json --out "$out/falling.html" --quiet
CHROMIUM="$chromium" node viewer/test/browser.mjs "$out/falling.html" "$out"

# tumble export-gltf's files through the Khronos glTF-Validator (viewer/test/gltf.mjs):
# every built-in scene, every kind of shape (also as .gltf with its buffer embedded), a
# z-up model.
gltf="$out/gltf"
rm -rf "$gltf" && mkdir -p "$gltf"
for scene in $(target/debug/tumble scenes | cut -d' ' -f1) viewer/test/every_shape.json viewer/test/z_up.json; do
    name=$(basename "$scene" .json)
    target/debug/tumble export-gltf "$scene" --out "$gltf/$name.glb" --duration 0.5 --quiet
done
target/debug/tumble export-gltf viewer/test/every_shape.json --out "$gltf/every_shape.gltf" --quiet
node viewer/test/gltf.mjs "$gltf"/*.glb "$gltf"/*.gltf

# And in a glTF viewer: three.js's GLTFLoader in headless Chromium (viewer/test/gltf_three.mjs)
# plays the falling ball's file; the ball is where the closed form puts it, in its colour.
target/debug/tumble export-gltf viewer/test/falling.json --out "$gltf/falling.glb" --quiet
CHROMIUM="$chromium" node viewer/test/gltf_three.mjs "$gltf/falling.glb" "$out"
