// A file of `tumble export-gltf` as a person sees it in a glTF viewer: three.js's
// GLTFLoader (the viewer's own three, bundled here by esbuild) reads it in headless
// Chromium, plays its animation, and the bodies are on the canvas in their colours where
// they are. The scene is viewer/test/falling.json: a red ball dropped from 5 m beside a
// blue box, dt = 0.01 s under symplectic Euler, so after n steps the ball is at
// y = 5 − g h² n (n + 1) / 2 exactly (to f32), 3.7505 m at t = 0.5 s.
// Usage: node test/gltf_three.mjs FILE.glb OUT_DIR
import { build } from 'esbuild';
import { chromium } from 'playwright-core';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const [glb_file, out_dir] = process.argv.slice(2);
mkdirSync(out_dir, { recursive: true });
const viewer = join(dirname(fileURLToPath(import.meta.url)), '..');
const bundle = await build({
  stdin: {
    contents: "import * as THREE from 'three';\n" +
      "import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';\n" +
      'window.THREE = THREE; window.GLTFLoader = GLTFLoader;',
    resolveDir: viewer,
  },
  bundle: true, write: false, format: 'iife', target: 'es2020', logLevel: 'warning',
});
const page_file = join(out_dir, 'gltf.html');
writeFileSync(page_file, `<!doctype html><body style="margin:0">
<script>${bundle.outputFiles[0].text}</script>
<script>window.GLB = "${readFileSync(glb_file).toString('base64')}";</script></body>`);

let failed = 0;
function check(name, ok, detail = '') {
  if (!ok) failed++;
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}${detail ? `: ${detail}` : ''}`);
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-gpu', '--no-first-run', '--use-angle=swiftshader',
    '--enable-unsafe-swiftshader'],
});
try {
  const page = await browser.newPage({ viewport: { width: 640, height: 480 } });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.route('**/*', (r) => (r.request().url().startsWith('file:') ? r.continue() : r.abort()));
  await page.goto(pathToFileURL(resolve(page_file)).href);
  // Load, set the animation to time t, draw, and read the colour under each body's centre.
  const look = (t) => page.evaluate(async (t) => {
    const { THREE, GLTFLoader } = window;
    const bytes = Uint8Array.from(atob(window.GLB), (c) => c.charCodeAt(0));
    const gltf = await new GLTFLoader().parseAsync(bytes.buffer, '');
    const renderer = new THREE.WebGLRenderer({ preserveDrawingBuffer: true });
    renderer.setSize(640, 480);
    document.body.replaceChildren(renderer.domElement);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0xffffff);
    scene.add(new THREE.AmbientLight(0xffffff, 3));
    scene.add(gltf.scene);
    const mixer = new THREE.AnimationMixer(gltf.scene);
    gltf.animations.forEach((clip) => mixer.clipAction(clip).play());
    mixer.setTime(t);
    const camera = new THREE.PerspectiveCamera(45, 640 / 480, 0.1, 100);
    camera.position.set(0.75, 3, 9);
    camera.lookAt(0.75, 2.5, 0);
    renderer.render(scene, camera);
    const gl = renderer.getContext();
    const seen = {};
    for (const name of ['ball', 'crate']) {
      const p = gltf.scene.getObjectByName(name).getWorldPosition(new THREE.Vector3());
      const s = p.clone().project(camera);
      const x = Math.round((s.x + 1) / 2 * 640), y = Math.round((1 - s.y) / 2 * 480);
      const px = new Uint8Array(4);
      gl.readPixels(x, 480 - y, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
      seen[name] = { position: p.toArray(), rgb: Array.from(px.slice(0, 3)) };
    }
    seen.animations = gltf.animations.length;
    seen.duration = gltf.animations[0].duration;
    seen.image = renderer.domElement.toDataURL();
    return seen;
  }, t);

  // The scene's sRGB colours, as drawn under a white ambient light of three's default
  // colour management: within 16 of each channel (a base colour not decoded to linear
  // would show #20 as about #63).
  const near = (want) => (c) => c.every((x, i) => Math.abs(x - want[i]) <= 16);
  const red = near([0xff, 0x00, 0x00]);
  const blue = near([0x20, 0x40, 0xe0]);
  for (const [t, n] of [[0, 0], [0.5, 50]]) {
    const seen = await look(t);
    writeFileSync(join(out_dir, `gltf-${t}.png`), Buffer.from(seen.image.split(',')[1], 'base64'));
    check(`one animation of 1 s (t = ${t})`, seen.animations === 1 && Math.abs(seen.duration - 1) < 1e-6,
      `${seen.animations}, ${seen.duration} s`);
    const y = 5 - 9.8 * 1e-4 * n * (n + 1) / 2;
    // f32 keyframes of a position near 4 m: 5e-7 m an ulp; 1e-5 leaves room.
    check(`ball at y = ${y.toFixed(4)} m (t = ${t})`, Math.abs(seen.ball.position[1] - y) < 1e-5,
      JSON.stringify(seen.ball.position));
    check(`red ball drawn at its centre (t = ${t})`, red(seen.ball.rgb), `${seen.ball.rgb}`);
    check(`blue box drawn at its centre (t = ${t})`, blue(seen.crate.rgb), `${seen.crate.rgb}`);
  }
  check('no console errors', errors.length === 0, errors.join(' | '));
} finally {
  await browser.close();
}
if (failed > 0) process.exit(1);
