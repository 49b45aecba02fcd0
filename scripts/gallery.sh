#!/bin/sh
# Encodes the viewer's default gallery into out/ (skipping models already
# encoded): the Stanford dragon mesh, the dragon with vertex colours, its
# vertices as a point cloud, a triangle soup (the triceratops with every
# triangle on its own vertices), a tetrahedral mesh (TetGen's Delaunay
# tetrahedralization of a ball) and the coloured dragon as a glTF scene
# with a kdmesh stream (KDMESH_progressive_compression).
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
# The dragon's ascii PLY with red, green and blue per vertex: jade at the
# base to gold at the top, banded along x.
if [ ! -f build/models/dragon-colours.ply ]; then
  node -e '
    const fs = require("fs");
    const text = fs.readFileSync("build/models/dragon_vrip.ply", "latin1");
    const end = text.indexOf("end_header\n") + "end_header\n".length;
    const header = text.slice(0, end).replace("property float z\n", "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n");
    const lines = text.slice(end).split("\n");
    const n = Number(/element vertex (\d+)/.exec(header)[1]);
    const xyz = lines.slice(0, n).map((line) => line.trim().split(/\s+/).map(Number));
    const low = [0, 1].map((a) => xyz.reduce((m, p) => Math.min(m, p[a]), Infinity));
    const high = [0, 1].map((a) => xyz.reduce((m, p) => Math.max(m, p[a]), -Infinity));
    const jade = [30, 120, 90], gold = [235, 180, 60];
    for (let i = 0; i < n; ++i) {
      const t = (xyz[i][1] - low[1]) / (high[1] - low[1]);
      const band = 0.85 + 0.15 * Math.cos((40 * (xyz[i][0] - low[0])) / (high[0] - low[0]));
      const rgb = jade.map((c, k) => Math.round(band * (c + t * (gold[k] - c))));
      lines[i] = lines[i].trim() + " " + rgb.join(" ");
    }
    fs.writeFileSync("build/models/dragon-colours.ply.tmp", header + lines.join("\n"));
  '
  mv build/models/dragon-colours.ply.tmp build/models/dragon-colours.ply
fi
encode() {  # encode OUTPUT INPUT OPTIONS...
  out=out/$1
  shift
  # Re-encode when the encoder is newer than the file.
  if [ ! -f "$out" ] || [ ./build/kdmesh -nt "$out" ]; then ./build/kdmesh encode "$@" -o "$out" -q; fi
}
encode dragon.kdm build/models/dragon_vrip.ply --bits 12
encode dragon-colours.kdm build/models/dragon-colours.ply --bits 12
encode dragon-points.kdm build/models/dragon_vrip.ply --bits 12 --points-only
encode triceratops-soup.kdm build/models/triceratops-soup.obj --bits 12
encode ball-tetrahedra.kdm build/models/ball10k.1.ele --bits 16
# The coloured dragon as plain glTF (its 12-bit positions, COLOR_0), then
# with its primitive as a kdmesh stream.
if [ ! -f build/models/dragon-colours.glb ] || [ out/dragon-colours.kdm -nt build/models/dragon-colours.glb ]; then
  ./build/kdmesh decode out/dragon-colours.kdm -o build/models/dragon-colours.glb -q
fi
encode dragon-colours.kdm.glb build/models/dragon-colours.glb --bits 12
