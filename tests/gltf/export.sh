#!/bin/sh
# Writes the .glb files the glTF checks read: the baked targets, a calm and a deep physics run, two affects
# played without physics, and a deep run of the male preset built with its shoulder girdle (clavicles,
# scapulae and arms). Usage: export.sh PNEUMA_CLI OUT_DIR ANATOMY_DIR
set -eu
cli=$1
out=$2
anatomy=$3
rm -rf "$out"
mkdir -p "$out"
"$cli" bake --out "$out/morphs.glb"
"$cli" simulate --style calm --duration 9 --out "$out/calm" --gltf "$out/calm.glb" --morphs "$out/morphs.glb"
"$cli" simulate --style deep --duration 6 --out "$out/deep" --gltf "$out/deep.glb" --morphs "$out/morphs.glb"
"$cli" play --affect fear --duration 10 --gltf "$out/fear.glb" --morphs "$out/morphs.glb"
"$cli" play --affect relaxation --duration 12 --gltf "$out/relaxation.glb" --morphs "$out/morphs.glb"
# the girdle model: the shipped anatomy with the option on
"$cli" model build --anatomy "$anatomy/male.json" --shoulder-girdle --out "$out/girdle-model" --no-preview
"$cli" simulate --model "$out/girdle-model" --style deep --duration 6 --out "$out/girdle-deep" \
  --gltf "$out/girdle-deep.glb"
