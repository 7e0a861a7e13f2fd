// The files of `tumble export-gltf` through the Khronos glTF-Validator (the reference
// implementation of the glTF 2.0 specification's rules: schema, buffer and accessor
// layout, accessor bounds, animation inputs, unit quaternions, ...). Any error, warning,
// info or hint fails the run.
// Usage: node viewer/test/gltf.mjs FILE.glb|FILE.gltf ...   (scripts/browser-test.sh)
import { readFileSync } from 'node:fs';
import validator from 'gltf-validator';

const files = process.argv.slice(2);
let failed = 0;
for (const file of files) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
    maxIssues: 100,
  });
  const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
  const info = report.info;
  console.log(
    `${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ` +
      `${numHints} hints (${info.totalVertexCount} vertices, ${info.animationCount} animation)`,
  );
  for (const m of messages) {
    console.log(`  ${m.severity} ${m.code} ${m.pointer}: ${m.message}`);
  }
  if (numErrors + numWarnings + numInfos + numHints > 0) {
    failed += 1;
  }
}
if (files.length === 0 || failed > 0) {
  console.error(`glTF validation: ${failed} of ${files.length} files with issues`);
  process.exit(1);
}
console.log(`glTF validation: ${files.length} files, no issues`);
