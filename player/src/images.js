// Decoding the export's images into texel arrays: PNGs by fast-png (it keeps the flows'
// 16 bits, which a canvas would cut to 8), JPEGs by the browser (grey atlases; no colour
// conversion, no premultiplication; WebCodecs' ImageDecoder where it has it).
import { decode as decodePng } from 'fast-png';
import { BadFile, imageBytes } from './glb.js';

/** A PNG image of the export as { width, height, channels, depth, data }. */
export function png(glb, index, what) {
  const { bytes, mime } = imageBytes(glb, index);
  if (mime !== 'image/png') throw new BadFile(glb.name, `${what}: ${mime}, expected image/png`);
  try {
    const p = decodePng(bytes);
    return { width: p.width, height: p.height, channels: p.channels, depth: p.depth, data: p.data };
  } catch (e) {
    throw new BadFile(glb.name, `${what}: the PNG does not decode (${e.message})`);
  }
}

/**
 * A grey JPEG's codes (the first channel), { width, height, data: Uint8Array }: decoded by
 * WebCodecs' ImageDecoder where the browser has it (no canvas to read back: half the time
 * of the canvas, the same codes on all 324 atlases of the small preset's pose), else
 * through a canvas.
 */
export async function greyJpeg(glb, index, what) {
  const { bytes, mime } = imageBytes(glb, index);
  if (mime !== 'image/jpeg') throw new BadFile(glb.name, `${what}: ${mime}, expected image/jpeg`);
  if (typeof ImageDecoder === 'undefined') return greyJpegByCanvas(glb, bytes, mime, what);
  let frame;
  let decoder;
  try {
    decoder = new ImageDecoder({ data: bytes, type: mime, colorSpaceConversion: 'none' });
    frame = (await decoder.decode()).image;
    const [width, height] = [frame.codedWidth, frame.codedHeight];
    const pixels = new Uint8Array(frame.allocationSize());
    const layout = await frame.copyTo(pixels);
    // One byte of each pixel: every channel of a grey JPEG holds its code.
    const step = layout[0].stride / width;
    const data = new Uint8Array(width * height);
    for (let y = 0; y < height; y++) {
      const row = layout[0].offset + y * layout[0].stride;
      for (let x = 0; x < width; x++) data[y * width + x] = pixels[row + x * step];
    }
    return { width, height, data };
  } catch (e) {
    throw new BadFile(glb.name, `${what}: the JPEG does not decode (${e.message})`);
  } finally {
    frame?.close();
    decoder?.close();
  }
}

/** [`greyJpeg`] through a canvas (browsers without ImageDecoder). */
async function greyJpegByCanvas(glb, bytes, mime, what) {
  let bitmap;
  try {
    bitmap = await createImageBitmap(new Blob([bytes], { type: mime }),
      { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
  } catch (e) {
    throw new BadFile(glb.name, `${what}: the JPEG does not decode (${e.message})`);
  }
  const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
  const ctx = canvas.getContext('2d', { willReadFrequently: true });
  ctx.drawImage(bitmap, 0, 0);
  const rgba = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
  const data = new Uint8Array(bitmap.width * bitmap.height);
  for (let i = 0; i < data.length; i++) data[i] = rgba[4 * i];
  bitmap.close();
  return { width: canvas.width, height: canvas.height, data };
}

/** Checks an image's size and channels against what the extension says it is. */
export function expect(glb, image, width, height, channels, what) {
  if (image.width !== width || image.height !== height || (channels && image.channels !== channels)) {
    throw new BadFile(glb.name, `${what}: ${image.width}x${image.height}x${image.channels ?? 1}, expected ${width}x${height}x${channels ?? 1}`);
  }
}
