// Subject PSNR of frame B against frame A (PNGs as `frf render` and screenshot.mjs write
// them: 8-bit sRGB, straight alpha): linear premultiplied colour over the pixels either
// covers by half, peak A's brightest; and the mean difference of alpha.
//   node player/compare.mjs A.png B.png
import { readFileSync } from 'node:fs';
import { decode } from 'fast-png';

const linear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);
const [a, b] = process.argv.slice(2, 4).map((p) => decode(readFileSync(p)));
if (a.width !== b.width || a.height !== b.height || a.channels !== 4 || b.channels !== 4) {
  console.error('compare: two RGBA PNGs of one size expected');
  process.exit(1);
}
let se = 0;
let n = 0;
let peak = 0;
let alpha = 0;
for (let i = 0; i < a.width * a.height; i++) {
  const aa = a.data[4 * i + 3] / 255;
  const ab = b.data[4 * i + 3] / 255;
  alpha += Math.abs(aa - ab);
  if (aa <= 0.5 && ab <= 0.5) continue;
  for (let c = 0; c < 3; c++) {
    const x = linear(a.data[4 * i + c] / 255) * aa;
    const y = linear(b.data[4 * i + c] / 255) * ab;
    se += (x - y) ** 2;
    peak = Math.max(peak, x);
    n++;
  }
}
console.log(JSON.stringify({ subject_psnr_db: 10 * Math.log10((peak * peak) / (se / n)), subject_pixels: n / 3, alpha_mean_abs_diff: alpha / (a.width * a.height) }));
