// Validates .glb files with the Khronos glTF validator (npm gltf-validator) and prints
// its report's counts as one JSON line per file; exits 1 when any file has an error or
// cannot be read or parsed (its line then says why), 2 when no file is given. Every issue
// is counted: the validator is run without its cap on reported issues, which an export's
// thousands of infos would otherwise fill before the buffers and accessors are checked.
//   node player/validate.mjs walker.glb [more.glb ...]
import { readFile } from 'node:fs/promises';
import validator from 'gltf-validator';

const paths = process.argv.slice(2);
if (paths.length === 0) {
  console.error('usage: node player/validate.mjs FILE.glb [FILE.glb ...]');
  process.exit(2);
}
let failed = false;
for (const path of paths) {
  let report;
  try {
    const bytes = new Uint8Array(await readFile(path));
    report = await validator.validateBytes(bytes, { uri: path, maxIssues: 0 });
  } catch (e) {
    // A missing file, or bytes the validator cannot take at all.
    const why = e && e.code === 'ENOENT' ? 'file not found' : String(e?.message ?? e);
    console.log(JSON.stringify({ file: path, error: why }));
    failed = true;
    continue;
  }
  const issues = report.issues;
  const errors = issues.messages.filter((m) => m.severity === 0);
  // Warnings by code, and the images they point at (a check can say which are expected).
  const warningCodes = {};
  const warnedImages = new Set();
  for (const m of issues.messages.filter((w) => w.severity === 1)) {
    warningCodes[m.code] = (warningCodes[m.code] ?? 0) + 1;
    const image = /^\/images\/(\d+)/.exec(m.pointer ?? '');
    if (image) warnedImages.add(Number(image[1]));
  }
  console.log(JSON.stringify({
    file: path,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    truncated: Boolean(issues.truncated),
    first_errors: errors.slice(0, 5).map((m) => `${m.code} ${m.pointer ?? ''}: ${m.message}`),
    warning_codes: warningCodes,
    warned_images: [...warnedImages].sort((x, y) => x - y),
  }));
  if (issues.numErrors > 0 || issues.truncated) failed = true;
}
process.exit(failed ? 1 : 0);
