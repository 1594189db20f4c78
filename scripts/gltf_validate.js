#!/usr/bin/env node
// Validates glTF files with the Khronos glTF Validator (npm gltf-validator,
// installed globally by scripts/deps) and prints, per file,
//   FILE: N errors, N warnings, N infos
// then the errors (code, pointer, message). Exit 0 when no file has errors,
// 1 when some has, 3 when the validator is not installed.
const fs = require('fs');
const path = require('path');
let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  try {
    const root = require('child_process').execSync('npm root -g', {stdio: ['ignore', 'pipe', 'ignore']}).toString().trim();
    validator = require(path.join(root, 'gltf-validator'));
  } catch (e2) {
    console.error('gltf_validate: the npm package gltf-validator is not installed (scripts/deps installs it)');
    process.exit(3);
  }
}
(async () => {
  let failed = false;
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {maxIssues: 1000});
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos`);
    for (const m of i.messages)
      if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer || ''}: ${m.message}`);
    if (i.numErrors > 0) failed = true;
  }
  process.exit(failed ? 1 : 0);
})();
