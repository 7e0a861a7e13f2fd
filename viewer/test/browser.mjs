// Opens a page written by `tumble export-html` in headless Chromium (Debian's, driven by
// playwright-core) and checks what a person would see: no console errors, the bodies on
// the canvas in their colours, and the scrubber changing the picture. Screenshots go to
// the folder given as the second argument.
// Usage: node test/browser.mjs PAGE.html OUT_DIR
import { chromium } from 'playwright-core';
import { mkdirSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [page_file, out_dir] = process.argv.slice(2);
mkdirSync(out_dir, { recursive: true });
let passed = 0;
let failed = 0;
function check(name, ok, detail = '') {
  if (ok) passed++;
  else failed++;
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}${detail ? `: ${detail}` : ''}`);
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: [
    '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    // WebGL in software: Chromium no longer falls back to SwiftShader on its own.
    '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
  ],
});
try {
  const page = await browser.newPage({ viewport: { width: 960, height: 640 } });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  // The page must need nothing from the network: refuse every request but the file.
  await page.route('**/*', (route) => (route.request().url().startsWith('file:') ? route.continue() : route.abort()));
  await page.goto(pathToFileURL(resolve(page_file)).href);
  await page.waitForFunction(() => window.tumbleViewer && window.tumbleViewer.ready, null, { timeout: 20000 });
  await page.evaluate(() => window.tumbleViewer.pause());

  // The colour drawn at a canvas point, read back from the WebGL canvas.
  const sample = (i) => page.evaluate((i) => {
    const v = window.tumbleViewer;
    v.render();
    const gl = document.querySelector('#view canvas');
    const c = document.createElement('canvas');
    c.width = gl.width; c.height = gl.height;
    const g = c.getContext('2d');
    g.drawImage(gl, 0, 0);
    const s = v.screenPosition(i);
    const k = gl.width / gl.getBoundingClientRect().width;
    const px = g.getImageData(Math.round(s.x * k), Math.round(s.y * k), 1, 1).data;
    // Count strongly red pixels over the whole canvas too.
    const all = g.getImageData(0, 0, c.width, c.height).data;
    let red = 0;
    for (let j = 0; j < all.length; j += 4) if (all[j] > 90 && all[j + 1] < 50 && all[j + 2] < 50) red++;
    return { x: s.x, y: s.y, rgb: [px[0], px[1], px[2]], red, image: c.toDataURL() };
  }, i);

  const scrubTo = (frame) => page.evaluate((f) => {
    const s = document.getElementById('scrubber');
    s.value = f;
    s.dispatchEvent(new Event('input', { bubbles: true }));
  }, frame);

  const frames = await page.evaluate(() => window.tumbleViewer.frames);
  check('the page holds the recorded frames', frames === 31, `${frames} frames`);

  await scrubTo(0);
  const start = await sample(1);
  await page.screenshot({ path: `${out_dir}/start.png` });
  check('the ball is drawn red where it is', start.rgb[0] > 90 && start.rgb[1] < 60 && start.rgb[2] < 60, `rgb ${start.rgb} at (${start.x.toFixed(0)}, ${start.y.toFixed(0)})`);
  check('red pixels make a ball, not a smear', start.red > 100 && start.red < 40000, `${start.red} red pixels`);
  const crate = await sample(2);
  check('the box is drawn blue', crate.rgb[2] > 90 && crate.rgb[0] < 80, `rgb ${crate.rgb}`);

  await scrubTo(frames - 1);
  const end = await sample(1);
  await page.screenshot({ path: `${out_dir}/end.png` });
  check('moving the scrubber changes the picture', end.image !== start.image);
  check('the ball has fallen down the picture', end.y > start.y + 20, `y ${start.y.toFixed(0)} -> ${end.y.toFixed(0)}`);
  check('and is still drawn red there', end.rgb[0] > 90 && end.rgb[1] < 60 && end.rgb[2] < 60, `rgb ${end.rgb}`);
  const clock = await page.textContent('#clock');
  check('the clock shows the scrubbed time', clock.startsWith('t = 1.00 s'), clock);

  // Clicking the ball shows its state.
  const canvas = await page.locator('#view canvas').boundingBox();
  await page.mouse.click(canvas.x + end.x, canvas.y + end.y);
  const info = await page.textContent('#info');
  check('clicking the ball shows its position, velocity, ω and L', /ball/.test(info) && /velocity/.test(info) && /ω/.test(info) && /L /.test(info), JSON.stringify(info.split('\n')[0]));
  await page.screenshot({ path: `${out_dir}/selected.png` });

  // The play button runs time forward again.
  await scrubTo(0);
  await page.click('#play');
  await page.waitForTimeout(600);
  const playing = await page.evaluate(() => window.tumbleViewer.frame());
  check('play advances the frames', playing > 0, `frame ${playing}`);

  check('no console errors', errors.length === 0, errors.join(' | '));
} finally {
  await browser.close();
}
console.log(`browser: ${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
