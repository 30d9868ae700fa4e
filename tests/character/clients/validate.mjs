// The Khronos glTF validator on each file named: one JSON line per file, errors and warnings.
import fs from 'node:fs';
import validator from 'gltf-validator';

for (const file of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), { uri: file, maxIssues: 50 });
  const issues = report.issues;
  console.log(JSON.stringify({
    file, errors: issues.numErrors, warnings: issues.numWarnings,
    messages: issues.messages.filter((m) => m.code !== 'UNSUPPORTED_EXTENSION').map((m) => [m.code, m.pointer]),
  }));
}
