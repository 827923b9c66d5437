// Validates .glb files with the Khronos glTF validator (npm gltf-validator) and prints
// its report's counts as one JSON line per file; exits 1 when any file has an error.
//   node player/validate.mjs walker.glb [more.glb ...]
import { readFile } from 'node:fs/promises';
import validator from 'gltf-validator';

let failed = false;
for (const path of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(path));
  const report = await validator.validateBytes(bytes, { uri: path, maxIssues: 50 });
  const issues = report.issues;
  const errors = issues.messages.filter((m) => m.severity === 0);
  console.log(JSON.stringify({
    file: path,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    first_errors: errors.slice(0, 5).map((m) => `${m.code} ${m.pointer ?? ''}: ${m.message}`),
  }));
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
