// texlume viewer, first script of the page (a classic script, run before the
// three.js modules are parsed): starts fetching the model and decoding the PTM
// textures at once, so that work overlaps loading the scripts. viewer.js
// takes the results from window.texlumePrefetch.
'use strict';
(() => {
  const fetchOk = async (url, kind) => {
    const response = await fetch(url);
    if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
    return kind === 'json' ? response.json() : kind === 'blob' ? response.blob() : response.arrayBuffer();
  };
  // Decoded off the main thread, flipped so that the first row is at v = 1,
  // with no colour-space conversion or premultiplication (raw coefficients).
  const decode = async (name) => {
    const blob = await fetchOk(`/model/${name}`, 'blob');
    try {
      return await createImageBitmap(blob, { imageOrientation: 'flipY', premultiplyAlpha: 'none', colorSpaceConversion: 'none' });
    } catch (e) {
      throw new Error(`/model/${name} could not be decoded`);
    }
  };
  const scene = fetchOk('/model/scene.json', 'json');
  const prefetch = {
    started: performance.now(),
    decode,
    scene,
    geometry: scene.then((s) => fetchOk('/model/' + s.geometry.file, 'binary')),
    // Per atlas: its PTM textures, decoded.
    ptmTextures: scene.then((s) => s.atlases.map((atlas) => Promise.all(atlas.textures.map((t) => decode(t.file))))),
    // Per atlas: its horizon textures (the relief's self-shadowing), none without one.
    horizonTextures: scene.then((s) => s.atlases.map((atlas) =>
      Promise.all(atlas.horizon ? atlas.horizon.files.map((f) => decode(f)) : []))),
  };
  // Rejections are handled by viewer.js; keep the console free of unhandled ones meanwhile.
  for (const p of [prefetch.scene, prefetch.geometry, prefetch.ptmTextures, prefetch.horizonTextures])
    p.catch(() => {});
  window.texlumePrefetch = prefetch;
})();
