#!/bin/sh
# Writes the .glb files the glTF checks read: the baked targets, a calm and a deep physics run (the deep one
# lifts the shoulder girdle), two affects played without physics. Usage: export.sh PNEUMA_CLI OUT_DIR
set -eu
cli=$1
out=$2
rm -rf "$out"
mkdir -p "$out"
"$cli" bake --out "$out/morphs.glb"
"$cli" simulate --style calm --duration 9 --out "$out/calm" --gltf "$out/calm.glb" --morphs "$out/morphs.glb"
"$cli" simulate --style deep --duration 6 --out "$out/deep" --gltf "$out/deep.glb" --morphs "$out/morphs.glb"
"$cli" play --affect fear --duration 10 --gltf "$out/fear.glb" --morphs "$out/morphs.glb"
"$cli" play --affect relaxation --duration 12 --gltf "$out/relaxation.glb" --morphs "$out/morphs.glb"
