// Validates glTF/GLB files with the Khronos glTF validator (npm `gltf-validator`).
// Usage: node validate.mjs <file.glb>...   (install first: `npm ci` in this folder)
// Prints one JSON line per file: {"file", "errors", "warnings", "infos", "messages"}; exits 1
// when any file has validation errors, 2 on a usage or I/O problem.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
let validator;
try {
  validator = require("gltf-validator");
} catch (e) {
  console.error(`gltf-validator is not installed: run \`npm ci\` in ${path.dirname(new URL(import.meta.url).pathname)}`);
  process.exit(2);
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node validate.mjs <file.glb>...");
  process.exit(2);
}

let failed = false;
for (const file of files) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 200,
    externalResourceFunction: (uri) =>
      fs.promises.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))),
  });
  const issues = report.issues;
  const messages = issues.messages.map((m) => `${["error", "warning", "info", "hint"][m.severity] ?? m.severity} ${m.code} ${m.pointer ?? ""}: ${m.message}`);
  console.log(JSON.stringify({ file, errors: issues.numErrors, warnings: issues.numWarnings, infos: issues.numInfos, messages }));
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
