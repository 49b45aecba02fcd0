// FNV-1a over the bits of a decoded model's arrays: the viewer publishes it
// for its complete model, and tests compare it with a Node decode of the
// same file.
export function modelChecksum(model) {
  let h = 0x811c9dc5;
  for (const array of [model.positions, model.points, model.edges, model.triangles, model.tetrahedra]) {
    const words = new Uint32Array(array.buffer, array.byteOffset, array.length);
    for (let i = 0; i < words.length; ++i) h = Math.imul(h ^ words[i], 0x01000193) >>> 0;
  }
  return h.toString(16);
}
