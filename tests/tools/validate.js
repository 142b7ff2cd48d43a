#!/usr/bin/env node
// validate.js FILE.(glb|gltf) [--max-warnings N]: runs the Khronos glTF
// validator (npm package gltf-validator, installed here by `npm ci`) on one
// file, prints {"file", "numErrors", "numWarnings", "errors": [...]} and exits
// 0 when there are no errors, 1 on errors, 2 on bad usage or a missing file.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
if (!file) {
    console.error('usage: validate.js FILE.glb|FILE.gltf');
    process.exit(2);
}
let bytes;
try {
    bytes = fs.readFileSync(file);
} catch (e) {
    console.error(`validate.js: cannot read ${file}: ${e.message}`);
    process.exit(2);
}
validator
    .validateBytes(new Uint8Array(bytes), {
        uri: path.basename(file),
        maxIssues: 200,
        externalResourceFunction: (uri) =>
            new Promise((resolve, reject) => {
                const p = path.resolve(path.dirname(file), decodeURIComponent(uri));
                fs.readFile(p, (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
            }),
    })
    .then((report) => {
        const issues = report.issues;
        const errors = issues.messages.filter((m) => m.severity === 0);
        console.log(JSON.stringify({
            file: file,
            numErrors: issues.numErrors,
            numWarnings: issues.numWarnings,
            errors: errors.map((m) => `${m.code} ${m.pointer || ''}: ${m.message}`),
            warnings: issues.messages.filter((m) => m.severity === 1).map((m) => `${m.code} ${m.pointer || ''}: ${m.message}`),
        }, null, 1));
        process.exit(issues.numErrors === 0 ? 0 : 1);
    })
    .catch((e) => {
        console.error(`validate.js: ${file}: ${e}`);
        process.exit(1);
    });
