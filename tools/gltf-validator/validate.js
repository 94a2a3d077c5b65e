#!/usr/bin/env node
// Validates glTF 2.0 files (.glb or .gltf) with the Khronos glTF validator installed next to this script
// (scripts/install-deps.sh: npm ci in tools/gltf-validator). Usage: node validate.js FILE...
// Prints one line per file (errors, warnings, infos) and every error message; exits 1 when any file has an error or
// cannot be read, 2 on bad usage.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function validateFile(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,  // all of them
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  });
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos, ` +
              `${issues.numHints} hints`);
  for (const m of issues.messages) {
    if (m.severity === 0 || process.env.FF_VALIDATOR_VERBOSE) {
      const kind = ['error', 'warning', 'info', 'hint'][m.severity];
      console.log(`  ${kind} ${m.code} at ${m.pointer || m.offset || '(file)'}: ${m.message}`);
    }
  }
  return issues.numErrors;
}

async function main() {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node validate.js FILE.glb...');
    process.exit(2);
  }
  let failed = 0;
  for (const f of files) {
    try {
      if ((await validateFile(f)) > 0) ++failed;
    } catch (e) {
      console.log(`${f}: cannot be validated: ${e}`);
      ++failed;
    }
  }
  if (failed > 0) {
    console.log(`${failed} of ${files.length} files have errors`);
    process.exit(1);
  }
  console.log(`all ${files.length} files valid (0 errors)`);
}

main();
