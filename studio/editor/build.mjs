// Bundles CodeMirror 6 (the packages package-lock.json pins, through
// entry.mjs) into one minified ES module for the studio's page,
// host-sim/src/studio/assets/codemirror.js, headed by the name, version and
// licence of every package in it. host-sim embeds it; it is committed
// because a machine without npm must still build host-sim.
//
//   npm ci && node build.mjs           writes the bundle
//   npm ci && node build.mjs --check   fails if the committed bundle is not
//                                      what these pinned sources make (CI)

import { build } from 'esbuild';
import { readFileSync, writeFileSync, readdirSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const out = join(here, '../../host-sim/src/studio/assets/codemirror.js');

const result = await build({
  entryPoints: [join(here, 'entry.mjs')],
  bundle: true,
  format: 'esm',
  platform: 'browser',
  target: 'es2020',
  minify: true,
  legalComments: 'none',
  charset: 'utf8',
  metafile: true,
  write: false,
  logLevel: 'error',
});

// Every package a byte of the bundle comes from, with its licence text.
const packages = new Set();
for (const input of Object.keys(result.metafile.inputs)) {
  const match = /node_modules\/((?:@[^/]+\/)?[^/]+)\//.exec(input);
  if (match) packages.add(match[1]);
}
const notices = [...packages].sort().map((name) => {
  const folder = join(here, 'node_modules', name);
  const manifest = JSON.parse(readFileSync(join(folder, 'package.json'), 'utf8'));
  const licenceFile = readdirSync(folder).find((f) => /^licen[cs]e/i.test(f));
  if (!licenceFile) throw new Error(`${name} ships no licence file`);
  const text = readFileSync(join(folder, licenceFile), 'utf8').trim().replaceAll('*/', '* /');
  return `${name} ${manifest.version} (${manifest.license}):\n\n${text}`;
});
const banner = `/*! CodeMirror 6 for the octrace studio, bundled by studio/editor/build.mjs
 * from the packages studio/editor/package-lock.json pins. Do not edit: run
 * \`npm ci && node build.mjs\` in studio/editor. The packages and their licences:
 *
${notices.join('\n\n').split('\n').map((line) => (' * ' + line).trimEnd()).join('\n')}
 */
`;
const bundle = banner + result.outputFiles[0].text;

if (process.argv.includes('--check')) {
  let committed = '';
  try { committed = readFileSync(out, 'utf8'); } catch { /* missing: differs */ }
  if (committed !== bundle) {
    console.error(`${out} is not what studio/editor's pinned sources make: run \`npm ci && node build.mjs\` in studio/editor and commit it`);
    process.exit(1);
  }
  console.log(`${out}: as built from the pinned sources (${packages.size} packages)`);
} else {
  writeFileSync(out, bundle);
  console.log(`wrote ${out}: ${bundle.length} bytes from ${packages.size} packages`);
}
