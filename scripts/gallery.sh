#!/usr/bin/env bash
# Renders the README's gallery: docs/gallery/*.gif from the built-in scenes and the
# example URDF robot.
# Usage: scripts/gallery.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked -q -p tumble-cli --bin tumble
out=docs/gallery
mkdir -p "$out"
render() { target/release/tumble render "$@" --width 320 --height 240 --quiet; }
render free_fall      --out "$out/free_fall.gif"      --fps 20
render dzhanibekov    --out "$out/dzhanibekov.gif"    --fps 15 --duration 8
render pyramid        --out "$out/pyramid.gif"        --fps 12 --contacts
render pendulum_chain --out "$out/pendulum_chain.gif" --fps 20 --joints
render examples/robot/arm.urdf --out "$out/arm_urdf.gif" --fps 15 --duration 3
ls -l "$out"
