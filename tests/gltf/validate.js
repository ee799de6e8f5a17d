// Validates a glTF 2.0 file with the Khronos glTF-Validator and prints its report's counts and first
// messages as JSON: {"errors", "warnings", "infos", "messages"}. Exit status 0 when the file was read
// (whatever it holds), 2 when the validator could not run. Usage: node validate.js FILE.glb|FILE.gltf
'use strict';
const fs = require('fs');
const validator = require('gltf-validator');

const file = process.argv[2];
if (!file) {
  console.error('usage: node validate.js FILE.glb|FILE.gltf');
  process.exit(2);
}
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)), {uri: file, maxIssues: 100})
  .then((report) => {
    const issues = report.issues;
    console.log(JSON.stringify({
      errors: issues.numErrors,
      warnings: issues.numWarnings,
      infos: issues.numInfos,
      messages: issues.messages.slice(0, 20),
    }));
  })
  .catch((error) => {
    console.error(String(error));
    process.exit(2);
  });
