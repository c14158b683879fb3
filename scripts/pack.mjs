#!/usr/bin/env node
// Assemble the npm package `polyscene` in pkg/npm/ and pack it with `npm pack`
// into pkg/polyscene-VERSION.tgz (scripts/pack.sh builds pkg/ first).
//
//   pkg/npm/
//     package.json      npm/package.json, version and description from Cargo.toml
//     README.md         npm/README.md (the package's own, short, no relative links)
//     LICENSE-MIT, LICENSE-APACHE
//     web/              pkg/web: ES module, init() first; browsers, workers, bundlers
//       polyscene_inline.js  the same with the wasm inlined (base64): zero bundler config
//       polyscene_sim.js, polyscene_sim_bg.wasm, polyscene_sim_inline.js
//                       the same for polyscene/sim (the simulator: a wasm of its own)
//     node/             pkg/node as polyscene.cjs (ready on require; it reads
//                       web/polyscene_bg.wasm, the same file), polyscene.mjs (its
//                       ES module face: one wasm instance for both); the same
//                       for polyscene_sim
//     worker/           www/src/worker.js and client.js (polyscene/worker), index.js
//     geo/              js/geo.mjs and js/geo.d.mts as index.js, index.d.ts (polyscene/geo;
//                       the dependency proj4 is for it)
//     io/               js/io.mjs and js/io.d.mts as index.js, index.d.ts (polyscene/io;
//                       the dependencies @loaders.gl/las and its peer @loaders.gl/core
//                       are for it); js/io-node.mjs as node.js (polyscene/io/node)
//
// Every other file or folder under npm/ is copied as it is: a new subpath
// (say polyscene/geo) is a folder npm/geo/ and one line in npm/package.json's
// "exports" ("files" is written here: every top-level entry of pkg/npm/).
//
// The generated JS and .d.ts are patched in two places, each checked here
// (the script fails when wasm-bindgen's output no longer has the pattern):
//   - wasm-bindgen writes its own `free()` and then ours (src/wasm: free() that
//     keeps the object and makes later calls throw a clear error) into one class
//     body; the later one wins, and bundlers warn `Duplicate member "free"`. The
//     generated one is removed: the class behaves exactly as before.
//   - the .d.ts names `Symbol.dispose`, which TypeScript's ES2022 libs lack
//     (`Property 'dispose' does not exist on type 'SymbolConstructor'`). The
//     .d.ts declares it (`readonly dispose: unique symbol`, as @types/node does),
//     which merges with lib.esnext.disposable where that is loaded.
// wasm-bindgen 0.2.130 has no option for either.

import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const src = path.join(root, 'npm');
const out = path.join(root, 'pkg/npm');

function fail(message) {
  console.error(`pack: ${message}`);
  process.exit(1);
}

const cargo = fs.readFileSync(path.join(root, 'Cargo.toml'), 'utf8');
const field = (name) => cargo.match(new RegExp(`^${name} = "([^"]*)"`, 'm'))?.[1] ?? fail(`no ${name} in Cargo.toml`);
const version = field('version');
const description = field('description');

// The two wasm builds of the crate (scripts/build-wasm.sh): the main module
// and the simulator's (polyscene/sim), each checked to export what it must.
const MODULES = [
  { name: 'polyscene', must: ['Scenario', 'detect'] },
  { name: 'polyscene_sim', must: ['simulate', 'Simulation'] },
];

for (const d of ['pkg/web', 'pkg/node']) {
  for (const { name } of MODULES) {
    if (!fs.existsSync(path.join(root, d, `${name}_bg.wasm`))) fail(`${d}/${name}_bg.wasm is missing: run scripts/build-wasm.sh`);
  }
}

fs.rmSync(out, { recursive: true, force: true });
fs.cpSync(src, out, { recursive: true });
for (const f of ['LICENSE-MIT', 'LICENSE-APACHE']) fs.copyFileSync(path.join(root, f), path.join(out, f));


/** Remove wasm-bindgen's own free() from every class that also has ours. */
function dedupeFreeJs(js, file) {
  const generated = /\n {4}free\(\) \{\n {8}const ptr = this\.__destroy_into_raw\(\);\n {8}wasm\.__wbg_\w+_free\(ptr, 0\);\n {4}\}/g;
  let removed = 0;
  const outJs = js.replace(/^(?:export )?class (\w+) \{\n[\s\S]*?^\}$/gm, (body) => {
    const ours = body.match(/^ {4}free\(\) \{$/gm)?.length ?? 0;
    if (ours < 2) return body;
    removed++;
    return body.replace(generated, '');
  });
  if (removed === 0) fail(`${file}: no class with two free() methods; has wasm-bindgen's output changed? (check this patch)`);
  for (const [, body] of outJs.matchAll(/^(?:export )?class \w+ \{\n([\s\S]*?)^\}$/gm)) {
    if ((body.match(/^ {4}free\(\) \{$/gm)?.length ?? 0) > 1) fail(`${file}: a class still has two free() methods`);
  }
  return outJs;
}

/** The same in the .d.ts (an undocumented `free(): void;` before the documented one), plus Symbol.dispose. */
function fixDts(dts, file) {
  let removed = 0;
  let fixed = dts.replace(/^(?:export )?class (\w+) \{\n[\s\S]*?^\}$/gm, (body) => {
    const frees = body.match(/^ {4}free\(\): void;$/gm)?.length ?? 0;
    if (frees < 2) return body;
    removed++;
    return body.replace(/^ {4}free\(\): void;\n/m, '');
  });
  if (removed === 0) fail(`${file}: no class declares free() twice; has wasm-bindgen's output changed? (check this patch)`);
  if (!fixed.includes('[Symbol.dispose](): void;')) fail(`${file}: no [Symbol.dispose]; drop this patch`);
  fixed = `${fixed.trimEnd()}

// Symbol.dispose (explicit resource management) is in TypeScript's esnext
// libs only; declared here so that this file compiles with the ES2022 libs.
// The methods exist at run time only where the engine has Symbol.dispose.
declare global {
    interface SymbolConstructor {
        readonly dispose: unique symbol;
    }
}
`;
  return fixed;
}

const read = (p) => fs.readFileSync(path.join(root, p), 'utf8');
const write = (p, text) => {
  fs.mkdirSync(path.dirname(path.join(out, p)), { recursive: true });
  fs.writeFileSync(path.join(out, p), text);
};

for (const { name, must } of MODULES) {
  // web/
  write(`web/${name}.js`, dedupeFreeJs(read(`pkg/web/${name}.js`), `pkg/web/${name}.js`));
  write(`web/${name}.d.ts`, fixDts(read(`pkg/web/${name}.d.ts`), `pkg/web/${name}.d.ts`));
  fs.copyFileSync(path.join(root, `pkg/web/${name}_bg.wasm`), path.join(out, `web/${name}_bg.wasm`));
  fs.copyFileSync(path.join(root, `pkg/web/${name}_bg.wasm.d.ts`), path.join(out, `web/${name}_bg.wasm.d.ts`));

  // web/NAME_inline.js: the wasm in the JS, so that a bundler needs no
  // asset handling at all (esbuild has no loader for .wasm by default).
  const wasmBase64 = fs.readFileSync(path.join(root, `pkg/web/${name}_bg.wasm`)).toString('base64');
  const subpath = name === 'polyscene' ? 'polyscene/inline' : 'polyscene/sim/inline';
  write(
    `web/${name}_inline.js`,
    `// ${subpath}: the web build with ${name}_bg.wasm inlined (base64),
// for bundlers and pages that should not serve a separate .wasm file. Same
// exports; init() needs no argument (init({ module_or_path }) still works).
import initWasm, { initSync as initSyncWasm } from './${name}.js';
export * from './${name}.js';

const WASM_BASE64 = '${wasmBase64}';

function wasmBytes() {
  const text = atob(WASM_BASE64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
  return bytes;
}

/** Instantiate the inlined wasm (or the given one). Await once before anything else. */
export default function init(options) {
  return initWasm({ module_or_path: options?.module_or_path ?? wasmBytes() });
}

/** Synchronous instantiation of the inlined wasm (or the given one). */
export function initSync(options) {
  return initSyncWasm({ module: options?.module ?? wasmBytes() });
}
`,
  );

  // node/
  const nodeJs = dedupeFreeJs(read(`pkg/node/${name}.js`), `pkg/node/${name}.js`).replace(
    `/* @ts-self-types="./${name}.d.ts" */`,
    `/* @ts-self-types="./${name}.d.cts" */`,
  );
  // The Node build's wasm is the same file as the web build's: one copy, in web/.
  if (!fs.readFileSync(path.join(root, `pkg/node/${name}_bg.wasm`)).equals(fs.readFileSync(path.join(root, `pkg/web/${name}_bg.wasm`)))) {
    fail(`pkg/node and pkg/web have different ${name}_bg.wasm files`);
  }
  const wasmPathLine = `const wasmPath = \`\${__dirname}/${name}_bg.wasm\`;`;
  if (!nodeJs.includes(wasmPathLine)) fail(`pkg/node/${name}.js does not read the wasm with ${wasmPathLine}`);
  write(`node/${name}.cjs`, nodeJs.replace(wasmPathLine, `const wasmPath = require('path').join(__dirname, '..', 'web', '${name}_bg.wasm');`));
  write(`node/${name}.d.cts`, fixDts(read(`pkg/node/${name}.d.ts`), `pkg/node/${name}.d.ts`));
  const names = Object.keys(createRequire(import.meta.url)(path.join(out, `node/${name}.cjs`))).sort();
  if (!must.every((n) => names.includes(n))) fail(`node/${name}.cjs exports ${names.join(', ')}`);
  write(
    `node/${name}.mjs`,
    `// Node's ES module entry of ${name}: the CommonJS build (ready on import;
// it reads ${name}_bg.wasm from disk) under ES module names, so that
// import and require share one wasm instance. Generated by scripts/pack.mjs.
import { createRequire } from 'node:module';

const cjs = createRequire(import.meta.url)('./${name}.cjs');

export const { ${names.join(', ')} } = cjs;

/** Nothing to wait for in Node; here so that code written for the web build (\`await init()\`) runs unchanged. */
export default async function init() {
  return undefined;
}
`,
  );
  write(
    `node/${name}.d.mts`,
    `export * from "./${name}.cjs";

/** Nothing to wait for in Node; here so that code written for the web build (\`await init()\`) runs unchanged. */
export default function init(options?: unknown): Promise<void>;
`,
  );
}

// worker/: the page's worker and client; only the paths to the web builds differ.
for (const f of ['worker.js', 'client.js']) {
  let text = read(`www/src/${f}`);
  if (f === 'worker.js') {
    for (const { name } of MODULES) {
      const from = `from '../pkg/${name}.js';`;
      if (!text.includes(from)) fail(`www/src/worker.js does not import ${from}`);
      text = text.replace(from, `from '../web/${name}.js';`);
    }
  }
  write(`worker/${f}`, text);
}

// geo/: polyscene/geo (js/geo.mjs, its types js/geo.d.mts), unchanged.
write('geo/index.js', read('js/geo.mjs'));
write('geo/index.d.ts', read('js/geo.d.mts'));

// io/: polyscene/io (js/io.mjs, its types js/io.d.mts), unchanged, and
// polyscene/io/node (js/io-node.mjs: file paths), whose import of the
// readers names the package's file.
write('io/index.js', read('js/io.mjs'));
write('io/index.d.ts', read('js/io.d.mts'));
{
  const from = "from './io.mjs';";
  const text = read('js/io-node.mjs');
  if (!text.includes(from)) fail(`js/io-node.mjs does not import ${from}`);
  write('io/node.js', text.replace(from, "from './index.js';"));
  write('io/node.d.ts', read('js/io-node.d.mts').replace("from './io.mjs';", "from './index.js';"));
}

// The manifest: version and description from Cargo.toml; "files" is every
// top-level entry assembled here (npm adds package.json itself).
const manifest = JSON.parse(fs.readFileSync(path.join(out, 'package.json'), 'utf8'));
manifest.version = version;
manifest.description = description;
manifest.files = fs
  .readdirSync(out, { withFileTypes: true })
  .filter((e) => e.name !== 'package.json')
  .map((e) => (e.isDirectory() ? `${e.name}/` : e.name))
  .sort();
fs.writeFileSync(path.join(out, 'package.json'), `${JSON.stringify(manifest, null, 2)}\n`);
for (const [subpath, target] of Object.entries(manifest.exports)) {
  for (const file of typeof target === 'string' ? [target] : JSON.stringify(target).match(/"\.\/[^"]+"/g).map((q) => JSON.parse(q))) {
    if (!fs.existsSync(path.join(out, file))) fail(`exports["${subpath}"] names ${file}, which is missing`);
  }
}

// Nothing that points nowhere.
for (const file of fs.readdirSync(out, { recursive: true })) {
  const p = path.join(out, file);
  if (!fs.statSync(p).isFile() || p.endsWith('.wasm')) continue;
  const text = fs.readFileSync(p, 'utf8');
  if (text.includes('example.invalid')) fail(`${file} has a placeholder URL`);
  if (file.endsWith('.md')) {
    for (const [, link] of text.matchAll(/\]\(([^)]+)\)/g)) {
      if (!/^(https?:|mailto:|#)/.test(link)) fail(`${file}: relative link ${link} (it breaks on the registry's page)`);
    }
  }
}

const packed = JSON.parse(
  execFileSync('npm', ['pack', '--json', '--pack-destination', path.join(root, 'pkg')], { cwd: out, encoding: 'utf8' }),
)[0];
const summary = `${packed.filename}: ${packed.size} bytes packed, ${packed.unpackedSize} unpacked, ${packed.entryCount} files`;
fs.writeFileSync(path.join(root, 'pkg/npm-pack.txt'), `${summary}\n`);
console.log(`pack: ${summary} (pkg/${packed.filename})`);
