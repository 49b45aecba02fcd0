// Draws rate–distortion curves as an SVG: error (relative to the bounding-box
// diagonal) against bytes received, log–log, one colour per model, solid for
// the mean and dashed for the max error; a dotted vertical line marks where
// the model's single-rate Draco file (-cl 10, same quantization) completes.
//
//   node bench/plot-rd.mjs OUT.svg NAME=CSV[:DRACO_BYTES]...
import { readFileSync, writeFileSync } from 'node:fs';

const [output, ...series] = process.argv.slice(2);
const data = series.map((spec) => {
  const [name, rest] = spec.split('=');
  const [csv, draco] = rest.split(':');
  const rows = readFileSync(csv, 'utf8').trim().split('\n').slice(1).map((l) => l.split(',').map(Number));
  return { name, rows: rows.filter((r) => r[2] > 0), draco: draco ? Number(draco) : null };
});
const width = 720, height = 440, left = 70, right = 20, top = 20, bottom = 50;
const all = data.flatMap((d) => d.rows);
const xs = all.map((r) => r[0]).concat(data.filter((d) => d.draco).map((d) => d.draco));
const ys = all.flatMap((r) => [r[2], r[3]]).filter((v) => v > 0);
const [x0, x1] = [Math.log10(Math.min(...xs)), Math.log10(Math.max(...xs))];
const [y0, y1] = [Math.floor(Math.log10(Math.min(...ys))), Math.ceil(Math.log10(Math.max(...ys)))];
const px = (x) => left + ((Math.log10(x) - x0) / (x1 - x0)) * (width - left - right);
const py = (y) => top + ((y1 - Math.log10(y)) / (y1 - y0)) * (height - top - bottom);
const colours = ['#1f6feb', '#d1242f', '#1a7f37', '#9a6700', '#8250df'];
const parts = [`<svg xmlns="http://www.w3.org/2000/svg" width="${width}" height="${height}" font-family="sans-serif" font-size="12">`,
  `<rect width="100%" height="100%" fill="white"/>`];
for (let e = y0; e <= y1; ++e) {
  parts.push(`<line x1="${left}" x2="${width - right}" y1="${py(10 ** e)}" y2="${py(10 ** e)}" stroke="#eee"/>`,
    `<text x="${left - 6}" y="${py(10 ** e) + 4}" text-anchor="end">1e${e}</text>`);
}
for (let e = Math.ceil(x0); e <= Math.floor(x1); ++e) {
  parts.push(`<line y1="${top}" y2="${height - bottom}" x1="${px(10 ** e)}" x2="${px(10 ** e)}" stroke="#eee"/>`,
    `<text x="${px(10 ** e)}" y="${height - bottom + 16}" text-anchor="middle">${10 ** e >= 1e6 ? `${10 ** (e - 6)} MB` : 10 ** e >= 1e3 ? `${10 ** (e - 3)} kB` : `${10 ** e} B`}</text>`);
}
parts.push(`<text x="${(left + width - right) / 2}" y="${height - 12}" text-anchor="middle">bytes received (log)</text>`,
  `<text transform="translate(16 ${(top + height - bottom) / 2}) rotate(-90)" text-anchor="middle">vertex error / bounding-box diagonal (log)</text>`);
data.forEach((d, i) => {
  const colour = colours[i % colours.length];
  for (const [column, dash] of [[2, ''], [3, ' stroke-dasharray="5 4"']]) {
    const points = d.rows.filter((r) => r[column] > 0).map((r) => `${px(r[0]).toFixed(1)},${py(r[column]).toFixed(1)}`).join(' ');
    parts.push(`<polyline fill="none" stroke="${colour}" stroke-width="2"${dash} points="${points}"/>`);
  }
  if (d.draco) parts.push(`<line x1="${px(d.draco)}" x2="${px(d.draco)}" y1="${top}" y2="${height - bottom}" stroke="${colour}" stroke-dasharray="2 3"/>`);
  parts.push(`<text x="${width - right - 8}" y="${top + 16 + 16 * i}" text-anchor="end" fill="${colour}">${d.name}${d.draco ? ' (dotted: Draco file complete)' : ''}</text>`);
});
parts.push(`<text x="${left + 8}" y="${height - bottom - 8}" fill="#555">solid: mean error · dashed: max error</text>`, '</svg>');
writeFileSync(output, parts.join('\n') + '\n');
