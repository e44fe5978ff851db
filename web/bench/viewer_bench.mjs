// How fast `texlume view` becomes interactive (issue 7: a 20k-triangle model
// within 2 s of opening). For every model folder given: the server's
// preparation time, the time from opening the page to its first frame, and the
// time per frame while the light moves (GPU work finished each frame), in
// headless Chromium with SwiftShader (a CPU rasteriser: an upper bound for
// any machine with a GPU). Run by bench/viewer_bench.sh:
//   TEXLUME=build/apps/texlume node web/bench/viewer_bench.mjs MODEL_DIR...
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

const texlume = process.env.TEXLUME;
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
const models = process.argv.slice(2);
if (!texlume || models.length === 0) {
  console.error('usage: TEXLUME=PROGRAM node viewer_bench.mjs MODEL_DIR...');
  process.exit(2);
}
const kFrames = 30;
// Each model is opened this many times (alternating); the run with the median
// first frame is reported, with the range over all runs (the machine is noisy).
const kRuns = Number(process.env.RUNS || 3);

async function serve(modelDir) {
  const server = spawn(texlume, ['view', modelDir, '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
  const started = Date.now();
  const { url, prepareS } = await new Promise((resolve, reject) => {
    let text = '';
    const timer = setTimeout(() => reject(new Error(`texlume view ${modelDir}: no address in 300 s`)), 300000);
    server.stdout.on('data', (chunk) => {
      text += chunk;
      const match = text.match(/prepared in ([0-9.e+-]+) s[\s\S]*at (http:\/\/[^ ]+\/)/);
      if (match) { clearTimeout(timer); resolve({ url: match[2], prepareS: Number(match[1]) }); }
    });
    server.on('exit', (code) => reject(new Error(`texlume view exited with ${code}`)));
  });
  return { server, url, prepareS, serveS: (Date.now() - started) / 1000 };
}

const browser = await chromium.launch({
  executablePath: chromiumPath,
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const rows = [];
try {
  // The first model twice: the first run (a cold browser) is not reported.
  const schedule = [models[0]];
  for (let r = 0; r < kRuns; ++r) schedule.push(...models);
  for (const [run, modelDir] of schedule.entries()) {
    const { server, url, prepareS, serveS } = await serve(modelDir);
    try {
      const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
      const errors = [];
      page.on('pageerror', (e) => errors.push(e.message));
      const opened = Date.now();
      await page.goto(url);
      await page.waitForFunction(
          () => window.texlumeViewer && (window.texlumeViewer.ready || window.texlumeViewer.errors.length),
          null, { timeout: 300000 });
      const openToFrameMs = Date.now() - opened;
      const result = await page.evaluate((frames) => {
        const v = window.texlumeViewer;
        if (!v.ready) return { errors: v.errors };
        const times = [];
        for (let k = 0; k < frames; ++k) {
          const a = (2 * Math.PI * k) / frames;
          const t = performance.now();
          v.setLight(0.7 * Math.cos(a), 0.7 * Math.sin(a), 0.71);
          v.renderNow();
          v.finish();
          times.push(performance.now() - t);
        }
        times.sort((x, y) => x - y);
        return { faces: v.faces, firstFrameMs: v.firstFrameMs, marks: v.marks, medianFrameMs: times[times.length >> 1],
                 worstFrameMs: times[times.length - 1] };
      }, kFrames);
      if (result.errors || errors.length) throw new Error(`${modelDir}: ${[...(result.errors || []), ...errors].join('; ')}`);
      if (run > 0) rows.push({ model: modelDir, prepareS, serveS, openToFrameMs, ...result });
      await page.close();
    } finally {
      server.kill('SIGTERM');
    }
  }
} finally {
  await browser.close();
}
const median = models.map((model) => {
  const runs = rows.filter((r) => r.model === model).sort((a, b) => a.firstFrameMs - b.firstFrameMs);
  return { ...runs[runs.length >> 1], minFirstFrameMs: runs[0].firstFrameMs, maxFirstFrameMs: runs[runs.length - 1].firstFrameMs };
});
console.log(`| model | triangles | server prepare (s) | page opened to: scripts / geometry / PTM textures decoded / uploaded / first frame / baked textures (ms), median of ${kRuns} runs | first frame, range (ms) | frame while relighting, median / worst (ms) |`);
console.log('| --- | --- | --- | --- | --- | --- |');
for (const r of median) {
  const m = r.marks;
  console.log(`| ${r.model} | ${r.faces} | ${r.prepareS.toFixed(2)} | ` +
      `${[m.moduleStart, m.geometry, m.textures, m.uploaded, r.firstFrameMs, m.baked].map((t) => t.toFixed(0)).join(' / ')} | ` +
      `${r.minFirstFrameMs.toFixed(0)}-${r.maxFirstFrameMs.toFixed(0)} | ` +
      `${r.medianFrameMs.toFixed(1)} / ${r.worstFrameMs.toFixed(1)} |`);
}
if (median.length > 1) {
  const base = median[0];
  for (const r of median.slice(1))
    console.log(`${r.model} / ${base.model}: triangles x${(r.faces / base.faces).toFixed(1)}, ` +
        `prepare x${(r.prepareS / base.prepareS).toFixed(2)}, first frame x${(r.firstFrameMs / base.firstFrameMs).toFixed(2)}, ` +
        `frame x${(r.medianFrameMs / base.medianFrameMs).toFixed(2)}`);
}
console.log(JSON.stringify(rows));
