// A small PNG decoder for the browser tests (8-bit greyscale, RGB, RGBA;
// non-interlaced, as Chromium writes screenshots): `rgb` per pixel, and the
// decoded `pixels` with their `channels`.
import { inflateSync } from 'node:zlib';

export function decodePng(buffer) {
  let p = 8, width = 0, height = 0, colourType = 0, bitDepth = 0;
  const idat = [];
  while (p < buffer.length) {
    const length = buffer.readUInt32BE(p), type = buffer.toString('ascii', p + 4, p + 8);
    const data = buffer.subarray(p + 8, p + 8 + length);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      bitDepth = data[8];
      colourType = data[9];
      if (data[12] !== 0) throw new Error('interlaced PNGs are not supported');
    } else if (type === 'IDAT') {
      idat.push(data);
    }
    p += 12 + length;
  }
  const channels = { 0: 1, 2: 3, 4: 2, 6: 4 }[colourType];
  if (bitDepth !== 8 || !channels) throw new Error(`unsupported PNG (depth ${bitDepth}, type ${colourType})`);
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const out = Buffer.alloc(height * stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const a = x >= channels ? out[y * stride + x - channels] : 0;
      const b = y > 0 ? out[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? out[(y - 1) * stride + x - channels] : 0;
      let v = line[x];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) {
        const pp = a + b - c, pa = Math.abs(pp - a), pb = Math.abs(pp - b), pc = Math.abs(pp - c);
        v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      out[y * stride + x] = v & 255;
    }
  }
  // RGB per pixel.
  const rgb = new Uint8Array(width * height * 3);
  for (let i = 0; i < width * height; ++i)
    for (let k = 0; k < 3; ++k) rgb[i * 3 + k] = out[i * channels + Math.min(k, channels - 1)];
  return { width, height, rgb, channels, pixels: out };
}
