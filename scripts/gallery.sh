#!/bin/sh
# Encodes the viewer's default gallery into out/ (skipping models already
# encoded): the Stanford dragon mesh, its vertices as a point cloud, a
# triangle soup (the triceratops with every triangle on its own vertices)
# and a tetrahedral mesh (TetGen's Delaunay tetrahedralization of a ball).
set -eu
cd "$(dirname "$0")/.."
sh scripts/models.sh
mkdir -p out
if [ ! -f build/models/triceratops-soup.obj ]; then
  node -e '
    const fs = require("fs");
    const words = fs.readFileSync("build/models/triceratops.off", "utf8").split(/\s+/).filter(Boolean);
    let at = 1;
    const [n, f] = [Number(words[at++]), Number(words[at++])];
    at++;
    const v = [];
    for (let i = 0; i < n; ++i) v.push(words.slice(at, at += 3).join(" "));
    const out = ["# every triangle of the triceratops on its own three vertices"];
    for (let i = 0; i < f; ++i) {
      const k = Number(words[at++]);
      const face = words.slice(at, at += k).map(Number);
      for (let j = 1; j + 1 < k; ++j) {
        for (const c of [face[0], face[j], face[j + 1]]) out.push("v " + v[c]);
        out.push("f -3 -2 -1");
      }
    }
    fs.writeFileSync("build/models/triceratops-soup.obj", out.join("\n") + "\n");
  '
fi
encode() {  # encode OUTPUT INPUT OPTIONS...
  out=out/$1
  shift
  # Re-encode when the encoder is newer than the file.
  if [ ! -f "$out" ] || [ ./build/kdmesh -nt "$out" ]; then ./build/kdmesh encode "$@" -o "$out" -q; fi
}
encode dragon.kdm build/models/dragon_vrip.ply --bits 12
encode dragon-points.kdm build/models/dragon_vrip.ply --bits 12 --points-only
encode triceratops-soup.kdm build/models/triceratops-soup.obj --bits 12
encode ball-tetrahedra.kdm build/models/ball10k.1.ele --bits 16
