// End-to-end tests of `texlume view` in headless Chromium (Debian's chromium,
// driven by playwright-core) and of the exported GLB against the Khronos glTF
// validator. Run by tests/web/viewer_test.sh, which builds a small model:
//   TEXLUME=build/apps/texlume TEXLUME_MODEL=DIR node --test web/test/
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawn } from 'node:child_process';
import { copyFileSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import validator from 'gltf-validator';
import * as esbuild from 'esbuild';
import { decodePng } from './png.mjs';

const texlume = process.env.TEXLUME;
const modelDir = process.env.TEXLUME_MODEL;
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
if (!texlume || !modelDir) throw new Error('set TEXLUME (the program) and TEXLUME_MODEL (a model folder)');

let server, browser, page, url;
const consoleErrors = [];

before(async () => {
  server = spawn(texlume, ['view', modelDir, '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
  url = await new Promise((resolve, reject) => {
    let text = '';
    const timer = setTimeout(() => reject(new Error('texlume view printed no address in 60 s')), 60000);
    server.stdout.on('data', (chunk) => {
      text += chunk;
      const match = text.match(/at (http:\/\/[^ ]+\/)/);
      if (match) { clearTimeout(timer); resolve(match[1]); }
    });
    server.on('exit', (code) => reject(new Error(`texlume view exited with ${code}`)));
  });
  browser = await chromium.launch({
    executablePath: chromiumPath,
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
  });
  page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(e.message));
  await page.goto(url);
  await page.waitForFunction(
      () => window.texlumeViewer && (window.texlumeViewer.ready || window.texlumeViewer.errors.length),
      null, { timeout: 120000 });
  const firstFrameMs = await page.evaluate(() => window.texlumeViewer.firstFrameMs);
  console.log(`viewer: first frame ${firstFrameMs?.toFixed(0)} ms after the page started loading`);
});

after(async () => {
  if (browser) await browser.close();
  if (server) server.kill('SIGTERM');
});

// The canvas alone (panel hidden), decoded.
async function shot() {
  await page.evaluate(() => {
    document.getElementById('panel').style.visibility = 'hidden';
    window.texlumeViewer.renderNow();
  });
  const png = await page.screenshot();
  await page.evaluate(() => { document.getElementById('panel').style.visibility = 'visible'; });
  return decodePng(png);
}

const background = [32, 33, 36];
function objectMask(image) {
  const mask = new Uint8Array(image.width * image.height);
  for (let i = 0; i < mask.length; ++i) {
    let d = 0;
    for (let k = 0; k < 3; ++k) d += Math.abs(image.rgb[i * 3 + k] - background[k]);
    mask[i] = d > 12 ? 1 : 0;
  }
  return mask;
}

// Mean luminance of the object's left and right halves (split at its centroid).
function halves(image, mask) {
  let sx = 0, n = 0;
  for (let i = 0; i < mask.length; ++i) if (mask[i]) { sx += i % image.width; ++n; }
  const cx = sx / n;
  const sum = [0, 0], count = [0, 0];
  for (let i = 0; i < mask.length; ++i) {
    if (!mask[i]) continue;
    const side = i % image.width < cx ? 0 : 1;
    sum[side] += 0.2126 * image.rgb[i * 3] + 0.7152 * image.rgb[i * 3 + 1] + 0.0722 * image.rgb[i * 3 + 2];
    ++count[side];
  }
  return { left: sum[0] / count[0], right: sum[1] / count[1], pixels: n };
}

// Fraction of pixels that changed by more than 8 levels in some channel.
function changed(a, b) {
  let n = 0;
  for (let i = 0; i < a.width * a.height; ++i)
    for (let k = 0; k < 3; ++k)
      if (Math.abs(a.rgb[i * 3 + k] - b.rgb[i * 3 + k]) > 8) { ++n; break; }
  return n / (a.width * a.height);
}

// Drags on the light sphere to a point (fractions of its box, y down).
async function dragLight(fx, fy) {
  const box = await page.locator('#light').boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width * fx, box.y + box.height * fy, { steps: 4 });
  await page.mouse.up();
}

test('the page loads the model with no console errors', async () => {
  const state = await page.evaluate(() => ({ ready: window.texlumeViewer.ready, errors: window.texlumeViewer.errors,
                                             software: window.texlumeViewer.softwareRenderer,
                                             status: document.getElementById('status').textContent }));
  assert.deepEqual(state.errors, []);
  assert.equal(state.ready, true);
  // SwiftShader is recognised as a software rasteriser (drawn without multisampling).
  assert.equal(state.software, true);
  assert.match(state.status, /software WebGL/);
  const image = await shot();
  assert.ok(halves(image, objectMask(image)).pixels > 0.05 * image.width * image.height,
            'the model covers the view');
  assert.deepEqual(consoleErrors, []);
});

test('the PTM textures reach WebGL byte for byte, the alpha channel included', async () => {
  const scene = await (await fetch(url + 'model/scene.json')).json();
  assert.equal(scene.format, 'texlume-web-3');
  const atlas = scene.atlases[0];
  assert.equal(atlas.textures.length, atlas.format === 'LRGB' ? 2 : 5);
  // The test model casts the relief's shadows (tests/web/viewer_test.sh).
  assert.ok(atlas.horizon && atlas.horizon.files.length === 4, 'the atlas has its horizon textures');
  let lowAlpha = 0;
  for (let k = 0; k < atlas.textures.length; ++k) {
    const png = decodePng(Buffer.from(await (await fetch(url + 'model/' + atlas.textures[k].file)).arrayBuffer()));
    assert.equal(png.channels, 4);
    // A block at the atlas centre, where charts are.
    const w = 64, h = 64, x0 = (atlas.width - w) >> 1, y0 = (atlas.height - h) >> 1;
    const got = await page.evaluate(([k, x0, y0, w, h]) => window.texlumeViewer.ptmTextureBytes(0, k, x0, y0, w, h),
        [k, x0, y0, w, h]);
    let differ = 0;
    for (let y = 0; y < h; ++y)
      for (let x = 0; x < w; ++x)
        for (let c = 0; c < 4; ++c) {
          const row = atlas.height - 1 - (y0 + y);  // WebGL rows from v = 0 up
          const expected = png.pixels[(row * atlas.width + x0 + x) * 4 + c];
          if (got[(y * w + x) * 4 + c] !== expected) ++differ;
          if (c === 3 && expected < 128) ++lowAlpha;
        }
    assert.equal(differ, 0, `texture ${k}: ${differ} bytes differ`);
  }
  // Premultiplied alpha would have changed those texels' colour channels.
  assert.ok(lowAlpha > 0, 'the blocks should hold texels with a small alpha');
});

test('dragging the light to either side brightens the side facing it', async () => {
  await dragLight(0.06, 0.5);
  const lightText = await page.locator('#light-value').textContent();
  assert.match(lightText, /^\(-0\.\d+/, 'the light sphere reads a light from the left');
  const fromLeft = await shot();
  await dragLight(0.94, 0.5);
  const fromRight = await shot();
  const l = halves(fromLeft, objectMask(fromLeft)), r = halves(fromRight, objectMask(fromRight));
  console.log(`light from the left: left ${l.left.toFixed(1)}, right ${l.right.toFixed(1)}; ` +
              `from the right: left ${r.left.toFixed(1)}, right ${r.right.toFixed(1)}`);
  assert.ok(l.left > l.right + 10, 'lit from the left, the left half is brighter');
  assert.ok(r.right > r.left + 10, 'lit from the right, the right half is brighter');
  assert.ok(l.left > r.left + 10 && r.right > l.right + 10, 'each half follows the light');
});

test('every shading mode and overlay changes the picture', async () => {
  await page.evaluate(() => window.texlumeViewer.setLight(0.5, 0.3, 0.81));
  const ptm = await shot();
  const cases = [
    ['baked 2D texture', 'radio', 'baked'],
    ['flat (mean albedo)', 'radio', 'flat'],
    ['triangle seams', 'checkbox', 'seams'],
    ['atlas charts', 'checkbox', 'charts'],
    ['specular enhancement', 'checkbox', 'specular'],
  ];
  for (const [label, kind, value] of cases) {
    const input = kind === 'radio' ? page.locator(`input[name=mode][value=${value}]`) : page.locator(`#${value}`);
    await input.click();
    const image = await shot();
    const fraction = changed(ptm, image);
    console.log(`${label}: ${(100 * fraction).toFixed(1)} % of the pixels changed`);
    assert.ok(fraction > 0.005, `${label} changes the picture`);
    if (kind === 'radio') await page.locator('input[name=mode][value=ptm]').click();
    else await input.click();
    assert.ok(changed(ptm, await shot()) < 0.001, `${label} switched off restores the PTM view`);
  }
  assert.deepEqual(consoleErrors, []);
});

test('the exported GLB passes the Khronos glTF validator with no errors and no warnings', async () => {
  const bytes = new Uint8Array(readFileSync(join(modelDir, 'model.glb')));
  const report = await validator.validateBytes(bytes, { maxIssues: 100 });
  const errors = report.issues.messages.filter((m) => m.severity <= 1);
  console.log(`glTF validator: ${report.issues.numErrors} errors, ${report.issues.numWarnings} warnings, ` +
              `${report.issues.numInfos} infos`);
  assert.equal(report.issues.numErrors, 0, JSON.stringify(errors, null, 1));
  assert.equal(report.issues.numWarnings, 0, JSON.stringify(errors, null, 1));
  // The model casts the relief's shadows: every material carries its horizon's 4 textures.
  const view = new DataView(bytes.buffer, bytes.byteOffset);
  const gltf = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + view.getUint32(12, true))));
  for (const material of gltf.materials) {
    const horizon = material.extensions.TEXLUME_ptm_atlas.horizon;
    assert.ok(horizon, `${material.name} has TEXLUME_ptm_atlas.horizon`);
    assert.equal(horizon.sectors, 16);
    assert.equal(horizon.textures.length, 4);
    const planes = new Set(material.extensions.TEXLUME_ptm_atlas.planes.map((p) => p.index));
    const indices = horizon.textures.map((t) => t.index);
    assert.equal(new Set(indices).size, 4, 'four distinct horizon textures');
    for (const i of indices) assert.ok(i >= 0 && i < gltf.textures.length && !planes.has(i));
  }
});

// COLMAP's text model: cameras (PINHOLE) and images by name.
function readColmapText(dir) {
  const lines = (file) => readFileSync(join(dir, file), 'utf8').split('\n').filter((l) => l && l[0] !== '#');
  const cameras = new Map();
  for (const l of lines('cameras.txt')) {
    const [id, model, width, height, ...params] = l.trim().split(/\s+/);
    if (model !== 'PINHOLE') throw new Error(`camera ${id} is ${model}; the test needs PINHOLE`);
    const [fx, fy, cx, cy] = params.map(Number);
    cameras.set(id, { width: Number(width), height: Number(height), fx, fy, cx, cy });
  }
  const images = new Map();
  const imageLines = readFileSync(join(dir, 'images.txt'), 'utf8').split('\n').filter((l) => l[0] !== '#');
  for (let i = 0; i + 1 < imageLines.length; i += 2) {
    const f = imageLines[i].trim().split(/\s+/);
    if (f.length < 10) continue;
    images.set(f[9], { ...cameras.get(f[8]), qvec: f.slice(1, 5).map(Number), tvec: f.slice(5, 8).map(Number) });
  }
  return images;
}

// The camera's axes in the world: rows of R_cam_from_world (x right, y down, z forward).
function cameraAxes(view) {
  const [w, x, y, z] = view.qvec;
  return [
    [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
  ];
}

// The first photo's camera, a side light (from the camera's right and a little behind
// the object, so the terminator crosses the view where the coarse faces meet), and
// `texlume render --samples 1` of that view under it, in `work`.
function renderFirstPhotoUnderASideLight(work) {
  const photos = process.env.TEXLUME_PHOTOS;  // the scene's object/ folder
  assert.ok(photos, 'set TEXLUME_PHOTOS to the scene\'s object folder');
  const [name, view] = [...readColmapText(join(photos, 'sparse_txt')).entries()][0];
  const [right, , forward] = cameraAxes(view);
  const light = right.map((r, k) => 0.95 * r + 0.3 * forward[k]);
  writeFileSync(join(work, 'lights.json'), JSON.stringify({
    format: 'texlume-object-lights', frame: 'world',
    images: { [name]: [{ type: 'directional', direction: light, intensity: 1.0 }] } }));
  execFileSync(texlume, ['render', '--model', modelDir, '--cameras', join(photos, 'sparse'),
                         '--lights', join(work, 'lights.json'), '--out', join(work, 'render'),
                         '--samples', '1'], { stdio: 'ignore' });
  const png = name.replace(/\.[^.]*$/, '.png');
  return { name, view, light, png,
           rendered: decodePng(readFileSync(join(work, 'render', png))),
           mask: decodePng(readFileSync(join(work, 'render', 'masks', png))) };
}

test('the viewer draws what texlume render draws for the same camera and side light', async () => {
  const work = mkdtempSync(join(tmpdir(), 'texlume-view-'));
  try {
    const { name, view, light, rendered, mask } = renderFirstPhotoUnderASideLight(work);
    const viewPage = await browser.newPage({ viewport: { width: view.width, height: view.height } });
    await viewPage.goto(url);
    await viewPage.waitForFunction(() => window.texlumeViewer && window.texlumeViewer.ready, null,
                                   { timeout: 120000 });
    await viewPage.evaluate(([v, l]) => {
      document.getElementById('panel').style.visibility = 'hidden';
      window.texlumeViewer.setView(v, l);
    }, [view, light]);
    const drawn = decodePng(await viewPage.screenshot());
    await viewPage.close();
    // Inside the object, away from its outline (a 3 x 3 neighbourhood all inside).
    const w = view.width, h = view.height;
    const diffs = [];
    for (let y = 1; y + 1 < h; ++y) {
      for (let x = 1; x + 1 < w; ++x) {
        let inside = true;
        for (let dy = -1; dy <= 1; ++dy)
          for (let dx = -1; dx <= 1; ++dx) inside &&= mask.pixels[((y + dy) * w + x + dx) * mask.channels] === 255;
        if (!inside) continue;
        const i = y * w + x;
        let d = 0;
        for (let k = 0; k < 3; ++k) d = Math.max(d, Math.abs(drawn.rgb[i * 3 + k] - rendered.rgb[i * 3 + k]));
        diffs.push(d);
      }
    }
    diffs.sort((a, b) => a - b);
    const mean = diffs.reduce((s, d) => s + d, 0) / diffs.length;
    const p99 = diffs[Math.floor(0.99 * (diffs.length - 1))];
    console.log(`viewer against texlume render (${name}, side light): ${diffs.length} pixels, ` +
                `mean difference ${mean.toFixed(2)} levels, 99th percentile ${p99}`);
    assert.ok(diffs.length > 0.05 * w * h, 'the object covers the view');
    // With the light taken in the face frame alone (before): mean 1.78, 99th percentile 17.
    assert.ok(mean < 1.2, `mean difference ${mean.toFixed(2)} levels`);
    assert.ok(p99 <= 8, `99th percentile ${p99} levels`);
  } finally {
    rmSync(work, { recursive: true, force: true });
  }
  assert.deepEqual(consoleErrors, []);
});

// Texture `bytes` (RGBA8, width x height) read at texel position (x, y) (centres at
// integers), channel k, by 4 x 4 taps with `weights`, the point clamped to the
// texel centres and the taps to the edges (CatmullRomTaps of core/cubic_interpolation.h).
function filtered(bytes, width, height, x, y, k, weights) {
  x = Math.min(Math.max(x, 0), width - 1);
  y = Math.min(Math.max(y, 0), height - 1);
  const bx = Math.floor(x), by = Math.floor(y);
  const wx = weights(x - bx), wy = weights(y - by);
  let sum = 0;
  for (let a = 0; a < 4; ++a)
    for (let b = 0; b < 4; ++b) {
      const tx = Math.min(Math.max(bx - 1 + b, 0), width - 1);
      const ty = Math.min(Math.max(by - 1 + a, 0), height - 1);
      sum += wy[a] * wx[b] * bytes[(ty * width + tx) * 4 + k];
    }
  return sum / 255;
}
const catmullRomWeights = (t) => [-0.5 * t ** 3 + t * t - 0.5 * t, 1.5 * t ** 3 - 2.5 * t * t + 1,
                                   -1.5 * t ** 3 + 2 * t * t + 0.5 * t, 0.5 * t ** 3 - 0.5 * t * t];
const bilinearWeights = (t) => [0, 1 - t, t, 0];

test('the viewer\'s PTM reads are Catmull-Rom, as texlume render\'s, to within a level', async () => {
  const work = mkdtempSync(join(tmpdir(), 'texlume-ptm-reads-'));
  const server = createServer((request, response) => {
    const file = { '/': 'index.html', '/page.js': 'page.js' }[request.url];
    if (!file) { response.writeHead(404).end(); return; }
    response.writeHead(200, { 'Content-Type': file.endsWith('.js') ? 'text/javascript' : 'text/html' })
        .end(readFileSync(join(work, file)));
  });
  try {
    await esbuild.build({ entryPoints: [join(import.meta.dirname, '..', 'test_pages', 'ptm_reads_page.js')],
                          bundle: true, format: 'esm', outfile: join(work, 'page.js'), logLevel: 'silent' });
    writeFileSync(join(work, 'index.html'), '<!doctype html><body style="margin:0">' +
        '<canvas id="view"></canvas><script type="module" src="/page.js"></script></body>');
    await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
    const crPage = await browser.newPage({ viewport: { width: 200, height: 200 } });
    await crPage.goto(`http://127.0.0.1:${server.address().port}/`);
    await crPage.waitForFunction(() => window.ptmReadsPageReady, null, { timeout: 60000 });
    // Random texels (a fixed seed): detail at the finest scale, where the reads differ most.
    const width = 7, height = 5, scale = 8;
    let seed = 12345;
    const bytes = Array.from({ length: width * height * 4 }, () => {
      seed = (Math.imul(1103515245, seed) + 12345) >>> 0;  // mod 2^32
      return seed >>> 24;
    });
    const drawn = await crPage.evaluate(([b, w, h, s]) => window.drawPtmReads(b, w, h, s),
                                        [bytes, width, height, scale]);
    await crPage.close();
    let worst = 0, worstBilinear = 0, sum = 0, n = 0;
    for (let j = 0; j < height * scale; ++j)
      for (let i = 0; i < width * scale; ++i)
        for (let k = 0; k < 3; ++k) {
          const x = (i + 0.5) / scale - 0.5, y = (j + 0.5) / scale - 0.5;
          const shown = (v) => Math.min(255, Math.max(0, 255 * (0.25 + 0.5 * v)));
          const expected = shown(filtered(bytes, width, height, x, y, k, catmullRomWeights));
          const bilinear = shown(filtered(bytes, width, height, x, y, k, bilinearWeights));
          const d = Math.abs(drawn[(j * width * scale + i) * 4 + k] - expected);
          worst = Math.max(worst, d);
          worstBilinear = Math.max(worstBilinear, Math.abs(bilinear - expected));
          sum += d; ++n;
        }
    console.log(`viewer's PTM reads (ptmValues) against Catmull-Rom's: mean ${(sum / n).toFixed(2)} levels, ` +
                `worst ${worst.toFixed(2)} (a bilinear read would differ by up to ${worstBilinear.toFixed(1)})`);
    assert.ok(worstBilinear > 10, 'the texture tells Catmull-Rom from bilinear');
    assert.ok(worst <= 1.5, `worst difference ${worst.toFixed(2)} levels`);
  } finally {
    server.close();
    rmSync(work, { recursive: true, force: true });
  }
  assert.deepEqual(consoleErrors, []);
});

// Luminance minus its 7 x 7 box mean: the relief's detail, at pixels whose 7 x 7
// neighbourhood lies inside `inside`.
function detail(image, inside) {
  const w = image.width, h = image.height, r = 3;
  const luma = new Float64Array(w * h);
  for (let i = 0; i < w * h; ++i)
    luma[i] = 0.2126 * image.rgb[i * 3] + 0.7152 * image.rgb[i * 3 + 1] + 0.0722 * image.rgb[i * 3 + 2];
  const out = new Map();
  for (let y = r; y + r < h; ++y) {
    for (let x = r; x + r < w; ++x) {
      let sum = 0, all = true;
      for (let dy = -r; dy <= r && all; ++dy)
        for (let dx = -r; dx <= r; ++dx) {
          const j = (y + dy) * w + x + dx;
          if (!inside[j]) { all = false; break; }
          sum += luma[j];
        }
      if (all) out.set(y * w + x, luma[y * w + x] - sum / 49);
    }
  }
  return out;
}

function correlation(a, b) {
  let sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, n = 0;
  for (const [i, va] of a) {
    const vb = b.get(i);
    if (vb === undefined) continue;
    sa += va; sb += vb; saa += va * va; sbb += vb * vb; sab += va * vb; ++n;
  }
  const cov = sab / n - (sa / n) * (sb / n);
  return cov / Math.sqrt((saa / n - (sa / n) ** 2) * (sbb / n - (sb / n) ** 2));
}

test('three.js shows the GLB\'s relief where texlume render shows the PTM\'s', async () => {
  const work = mkdtempSync(join(tmpdir(), 'texlume-glb-'));
  const server = createServer((request, response) => {
    const file = { '/': 'index.html', '/page.js': 'page.js', '/model.glb': 'model.glb' }[request.url];
    if (!file) { response.writeHead(404).end(); return; }
    const type = { html: 'text/html', js: 'text/javascript', glb: 'model/gltf-binary' }[file.split('.').pop()];
    response.writeHead(200, { 'Content-Type': type }).end(readFileSync(join(work, file)));
  });
  try {
    const { name, view, light, png, rendered, mask } = renderFirstPhotoUnderASideLight(work);
    await esbuild.build({ entryPoints: [join(import.meta.dirname, '..', 'test_pages', 'glb_page.js')], bundle: true,
                          format: 'esm', outfile: join(work, 'page.js'), logLevel: 'silent' });
    writeFileSync(join(work, 'index.html'), '<!doctype html><body style="margin:0">' +
        `<canvas id="view" width="${view.width}" height="${view.height}"></canvas>` +
        '<script type="module" src="/page.js"></script></body>');
    copyFileSync(join(modelDir, 'model.glb'), join(work, 'model.glb'));
    await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
    const glbPage = await browser.newPage({ viewport: { width: view.width, height: view.height } });
    await glbPage.goto(`http://127.0.0.1:${server.address().port}/`);
    await glbPage.waitForFunction(() => window.glbPageReady, null, { timeout: 60000 });
    const draw = async (normalMap, flipGreen = false) => {
      const state = await glbPage.evaluate(
          ([v, l, m, f]) => window.drawGlb('/model.glb', v, l, { normalMap: m, flipGreen: f }),
          [view, light, normalMap, flipGreen]);
      assert.equal(state.tangents, true, 'the GLB\'s own tangents are used');
      const shotPng = await glbPage.screenshot();
      if (process.env.TEXLUME_SCREENSHOTS)
        writeFileSync(join(process.env.TEXLUME_SCREENSHOTS, `glb_${normalMap ? 'relief' : 'flat'}.png`), shotPng);
      return decodePng(shotPng);
    };
    const withRelief = await draw(true), withoutRelief = await draw(false);
    const flippedRelief = await draw(true, true);
    await glbPage.close();
    if (process.env.TEXLUME_SCREENSHOTS)
      copyFileSync(join(work, 'render', png), join(process.env.TEXLUME_SCREENSHOTS, 'render.png'));
    // The lit part (the rendering adds the model's ambient light on the dark side,
    // which a plain glTF viewer has no reason to know).
    const inside = new Uint8Array(view.width * view.height);
    for (let i = 0; i < inside.length; ++i)
      inside[i] = mask.pixels[i * mask.channels] === 255 && withoutRelief.rgb[i * 3 + 1] > 40 ? 1 : 0;
    const truth = detail(rendered, inside);
    const relief = correlation(detail(withRelief, inside), truth);
    const albedoOnly = correlation(detail(withoutRelief, inside), truth);
    const flipped = correlation(detail(flippedRelief, inside), truth);
    console.log(`GLB in three.js against texlume render (${name}, side light): detail correlation ` +
                `${relief.toFixed(3)} with the normal map, ${albedoOnly.toFixed(3)} without, ` +
                `${flipped.toFixed(3)} with its green read the other way`);
    assert.ok(relief > 0.45, `with the normal map: ${relief.toFixed(3)}`);
    assert.ok(relief > albedoOnly + 0.15, `the normal map adds the relief (${albedoOnly.toFixed(3)} without)`);
    assert.ok(relief > flipped + 0.1, `the map's convention is glTF's (${flipped.toFixed(3)} flipped)`);
  } finally {
    server.close();
    rmSync(work, { recursive: true, force: true });
  }
});
