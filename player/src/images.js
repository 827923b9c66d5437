// Decoding the export's images into texel arrays: PNGs by fast-png (it keeps the flows'
// 16 bits, which a canvas would cut to 8), JPEGs by the browser (grey atlases; no colour
// conversion, no premultiplication; WebCodecs' ImageDecoder where it has it), and KTX2
// atlases transcoded by three's KTX2Loader to the GPU's own block format (kept
// compressed: never decoded to texels here).
import * as THREE from 'three';
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

/** `n` rounded up to whole 4 x 4 blocks (a KTX2 atlas' padded size). */
export const blocks4 = (n) => Math.ceil(n / 4) * 4;

/**
 * A KTX2 atlas (UASTC blocks, `frf export --textures ktx2`) transcoded by `loader` (a
 * KTX2Loader set up for the renderer) to a block format the GPU samples (BC7, ASTC, ETC2:
 * whichever it has), or to RGBA8 texels where it has none: { width, height, format, type,
 * compressed, data } of its one level.
 */
export async function ktx2Atlas(glb, index, what, loader) {
  const { bytes, mime } = imageBytes(glb, index);
  if (mime !== 'image/ktx2') throw new BadFile(glb.name, `${what}: ${mime}, expected image/ktx2`);
  let texture;
  try {
    // The loader hands the buffer to its worker: a copy of the image's bytes.
    texture = await new Promise((ok, fail) => loader.parse(bytes.slice().buffer, ok, fail));
  } catch (e) {
    throw new BadFile(glb.name, `${what}: the KTX2 image does not transcode (${e?.message ?? e})`);
  }
  const level = texture.mipmaps?.[0];
  texture.dispose();
  if (!level || texture.isCompressedArrayTexture) throw new BadFile(glb.name, `${what}: not one 2D level`);
  return {
    width: level.width, height: level.height, format: texture.format, type: texture.type,
    compressed: texture.format !== THREE.RGBAFormat, data: level.data,
  };
}

/** Checks an image's size and channels against what the extension says it is. */
export function expect(glb, image, width, height, channels, what) {
  if (image.width !== width || image.height !== height || (channels && image.channels !== channels)) {
    throw new BadFile(glb.name, `${what}: ${image.width}x${image.height}x${image.channels ?? 1}, expected ${width}x${height}x${channels ?? 1}`);
  }
}
