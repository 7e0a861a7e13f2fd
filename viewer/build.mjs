// Bundles the viewer into one file: `node build.mjs [OUTFILE]` (default dist/viewer.js,
// the copy the tumble binary embeds). scripts/browser-test.sh builds to a scratch file
// and compares, so the committed bundle cannot drift from src/.
import { build } from 'esbuild';

await build({
  entryPoints: ['src/main.js'],
  bundle: true,
  minify: true,
  format: 'iife',
  target: 'es2020',
  legalComments: 'none',
  outfile: process.argv[2] || 'dist/viewer.js',
  logLevel: 'warning',
});
