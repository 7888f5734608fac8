// Loads a .glb in three.js inside headless Chromium (Debian's /usr/bin/chromium, driven by playwright-core),
// renders the animation at its deepest inspiration and half a breath earlier, writes both frames as PNG and
// checks that the body is drawn and that the two frames differ at the chest and at the belly.
// Usage: node render.mjs FILE.glb HALF_BREATH_S OUT_PREFIX [translucent]
// (translucent: the skin drawn at 30 % opacity over the bones, for pictures of the skeleton breathing)
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const [glb, halfBreath, outPrefix, mode] = process.argv.slice(2);
if (!glb || !halfBreath || !outPrefix) {
  console.error('usage: node render.mjs FILE.glb HALF_BREATH_S OUT_PREFIX');
  process.exit(2);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const three = path.join(here, 'node_modules', 'three');
const types = { '.html': 'text/html', '.js': 'text/javascript', '.glb': 'model/gltf-binary' };

// a local server for the page, three.js and the model
const server = http.createServer((req, res) => {
  const url = decodeURIComponent(req.url.split('?')[0]);
  let file = null;
  if (url === '/') file = path.join(here, 'render.html');
  else if (url === '/model.glb') file = path.resolve(glb);
  else if (url.startsWith('/three/')) file = path.join(three, path.normalize(url.slice('/three/'.length)));
  if (!file || (url.startsWith('/three/') && !file.startsWith(three + path.sep)) || !fs.existsSync(file)) {
    res.writeHead(404).end();
    return;
  }
  res.writeHead(200, { 'Content-Type': types[path.extname(file)] ?? 'application/octet-stream' });
  fs.createReadStream(file).pipe(res);
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const port = server.address().port;

const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'pneuma-chromium-'));
// a fresh profile, passed as playwright asks (launchPersistentContext) rather than as --user-data-dir
const context = await chromium.launchPersistentContext(profile, {
  headless: true,
  executablePath: process.env.PNEUMA_CHROMIUM ?? '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync',
         '--enable-unsafe-swiftshader', '--use-angle=swiftshader'],
});
let code = 1;
try {
  const page = await context.newPage();
  page.on('pageerror', (e) => console.error('page error:', e.message));
  await page.goto(`http://127.0.0.1:${port}/`);
  await page.waitForFunction(() => window.ready === true);
  const info = await page.evaluate((translucent) => window.load('/model.glb', translucent), mode === 'translucent');
  const t1 = info.peak, t0 = t1 - Number(halfBreath) >= 0 ? t1 - Number(halfBreath) : t1 + Number(halfBreath);
  const r = await page.evaluate(([a, b]) => window.compare(a, b, 30), [t0, t1]);
  for (const [name, png] of [['a', r.png0], ['b', r.png1]])
    fs.writeFileSync(`${outPrefix}-${name}.png`, Buffer.from(png.split(',')[1], 'base64'));
  const drawnShare = r.drawn / r.total;
  console.log(`frames at ${t0.toFixed(2)} s and ${t1.toFixed(2)} s (peak inspiration) of ${info.duration.toFixed(2)} s,` +
              ` ${info.weights} morph targets: body on ${(100 * drawnShare).toFixed(1)} % of the image;` +
              ` pixels changed in 60 px squares: chest ${r.chestChanged}, belly ${r.bellyChanged};` +
              ` wrote ${outPrefix}-a.png, ${outPrefix}-b.png`);
  const failures = [];
  // a torso framed at 30 degrees covers a fifth or more of the image; a stray triangle or an empty scene does not
  if (drawnShare < 0.15) failures.push(`body drawn on only ${(100 * drawnShare).toFixed(1)} % of the image (< 15 %)`);
  if (r.chestChanged < 20) failures.push(`chest: ${r.chestChanged} pixels changed between the frames (< 20)`);
  if (r.bellyChanged < 20) failures.push(`belly: ${r.bellyChanged} pixels changed between the frames (< 20)`);
  for (const f of failures) console.error(`FAIL ${f}`);
  code = failures.length === 0 ? 0 : 1;
} finally {
  await context.close();
  server.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
process.exit(code);
