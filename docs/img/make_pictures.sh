#!/usr/bin/env bash
# Regenerate the README's pictures with softhand inspect (CI meshes: a few minutes).
#   bash docs/img/make_pictures.sh [RESULTS_DIR]    (default results/pictures)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-results/pictures}
img=docs/img
softhand bend --mesher gmsh --mesh-size-mm 6 --pressure-mpa 0:2:0.25 --peak-mpa 0 --out "$out/bend" > /dev/null
softhand weights --diameter-mm 180 --mass-kg 2 --pressure-mpa 0.8 --mesh-size-mm 6 --out "$out/grasp" > /dev/null
softhand reservoir --volume-mm3 6000,12000,17800 --out "$out/reservoir" > /dev/null
softhand inspect "$out/bend/finger.pvd" --one-finger --field "principal_stretches[0]" --out "$img/finger.png"
softhand inspect "$out/grasp/grasp.pvd" --step 0 --out "$img/grasp.png"
softhand inspect "$out/reservoir/sheet.pvd" --field height_mm --out "$img/reservoir.png"
softhand inspect "$out/bend/finger.pvd" --field displacement_mm --animate "$img/bend.gif"
ls -l "$img"
