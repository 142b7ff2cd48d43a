#!/usr/bin/env node
// inspect.js FILE.(glb|gltf): loads a file with glTF Transform (npm
// @gltf-transform/core, a real glTF client, the SDK behind the
// `gltf-transform inspect` command) and prints what a player would get from it:
// {"file", "meshes", "skinnedPrimitives", "skins": [{"name", "joints"}],
//  "animations": [{"name", "channels", "duration"}], "problems": [...]}.
// A problem is anything that would keep the skin or the animation from
// playing: a JOINTS_0 without WEIGHTS_0 (or the other way round), a skinned
// mesh on a node without a skin, a joint index past its skin's joint list, a
// channel without a target node or with fewer than two keys or a zero or
// non-finite duration. Exit 0 when it loads with no problem, 1 when it loads
// with problems, 2 when it does not load or on bad usage.
'use strict';
const path = require('path');

async function main() {
    const file = process.argv[2];
    if (!file || process.argv.length > 3) {
        console.error('usage: inspect.js FILE.glb|FILE.gltf');
        return 2;
    }
    // An ESM import: the package's CommonJS build require()s an ES module,
    // which Node 18 (Debian 12's nodejs) cannot do.
    let NodeIO;
    try {
        ({ NodeIO } = await import('@gltf-transform/core'));
    } catch (e) {
        console.error(`inspect.js: cannot load @gltf-transform/core (run npm ci in tests/tools): ${e.message}`);
        return 2;
    }
    let doc;
    try {
        doc = await new NodeIO().read(file);
    } catch (e) {
        console.error(`inspect.js: ${file}: does not load: ${e.message}`);
        return 2;
    }
    const root = doc.getRoot();
    const problems = [];
    const skinOf = new Map(); // mesh -> skins of the nodes that instance it
    for (const node of root.listNodes()) {
        const mesh = node.getMesh();
        if (!mesh) continue;
        if (!skinOf.has(mesh)) skinOf.set(mesh, []);
        if (node.getSkin()) skinOf.get(mesh).push(node.getSkin());
    }
    let skinned = 0;
    for (const mesh of root.listMeshes()) {
        for (const prim of mesh.listPrimitives()) {
            const joints = prim.getAttribute('JOINTS_0');
            const weights = prim.getAttribute('WEIGHTS_0');
            if (!joints && !weights) continue;
            if (!joints || !weights) {
                problems.push(`mesh '${mesh.getName()}': JOINTS_0 and WEIGHTS_0 must come together`);
                continue;
            }
            skinned++;
            const skins = skinOf.get(mesh) || [];
            if (skins.length === 0) {
                problems.push(`mesh '${mesh.getName()}': skinned but no node with a skin instances it`);
                continue;
            }
            const bound = Math.min(...skins.map((s) => s.listJoints().length));
            const el = [];
            for (let i = 0; i < joints.getCount(); i++) {
                joints.getElement(i, el);
                weights.getElement(i, el.w || (el.w = []));
                for (let k = 0; k < 4; k++) {
                    if (el.w[k] > 0 && el[k] >= bound) {
                        problems.push(`mesh '${mesh.getName()}': vertex ${i} uses joint ${el[k]} of a ${bound}-joint skin`);
                        i = joints.getCount();
                        break;
                    }
                }
            }
        }
    }
    const animations = root.listAnimations().map((a) => {
        let lo = Infinity, hi = -Infinity;
        for (const ch of a.listChannels()) {
            const input = ch.getSampler() && ch.getSampler().getInput();
            if (!ch.getTargetNode()) problems.push(`animation '${a.getName()}': a channel has no target node`);
            if (!input || input.getCount() < 2) {
                problems.push(`animation '${a.getName()}': a channel has fewer than two keys`);
                continue;
            }
            lo = Math.min(lo, input.getMin([])[0]);
            hi = Math.max(hi, input.getMax([])[0]);
        }
        const duration = hi - lo;
        if (!(Number.isFinite(duration) && duration > 0))
            problems.push(`animation '${a.getName()}': duration is not positive`);
        return { name: a.getName(), channels: a.listChannels().length, duration: Number.isFinite(duration) ? duration : 0 };
    });
    const report = {
        file: path.basename(file),
        meshes: root.listMeshes().length,
        skinnedPrimitives: skinned,
        skins: root.listSkins().map((s) => ({ name: s.getName(), joints: s.listJoints().length })),
        animations,
        problems,
    };
    console.log(JSON.stringify(report));
    return problems.length ? 1 : 0;
}

main().then((rc) => process.exit(rc), (e) => {
    console.error(`inspect.js: ${e.message}`);
    process.exit(2);
});
