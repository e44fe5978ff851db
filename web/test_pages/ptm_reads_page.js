// Draws a small RGBA8 texture magnified through the viewer's own PTM reads
// (web/viewer/ptm_reads.js: ptmValues, as the viewer's shader calls it), as the
// first texture of an LRGB atlas, for the browser tests (web/test/viewer.test.mjs).
// Bundled by the test with esbuild. window.drawPtmReads(bytes, width, height,
// scale) returns the picture's RGBA bytes, rows from the bottom (texture row 0) up;
// each pixel shows 0.25 + 0.5 x the coefficients a0, a1, a2 read there (the
// texture's R, G, B at scale 1 and bias 0), so the filter's overshoot stays in range.
import * as THREE from 'three';
import { ptmReadsGlsl } from '../viewer/ptm_reads.js';

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;  // values as they are

window.drawPtmReads = (bytes, width, height, scale) => {
  const texture = new THREE.DataTexture(new Uint8Array(bytes), width, height);
  texture.minFilter = texture.magFilter = THREE.LinearFilter;  // as the viewer's atlases
  texture.generateMipmaps = false;
  texture.needsUpdate = true;
  const material = new THREE.ShaderMaterial({
    uniforms: {
      ptm0: { value: texture }, ptm1: { value: texture }, ptm2: { value: texture },
      ptm3: { value: texture }, ptm4: { value: texture },
      ptmScale: { value: Array.from({ length: 5 }, () => new THREE.Vector4(1, 1, 1, 1)) },
      ptmBias: { value: Array.from({ length: 5 }, () => new THREE.Vector4(0, 0, 0, 0)) },
      ptmSize: { value: new THREE.Vector2(width, height) },
      lrgb: { value: true },
    },
    vertexShader: 'varying vec2 vUv;\nvoid main() { vUv = uv; gl_Position = vec4(position.xy, 0.0, 1.0); }',
    fragmentShader: `precision highp float;
varying vec2 vUv;
${ptmReadsGlsl}
void main() {
  vec3 c[6];
  vec3 colour;
  ptmValues(c, colour);
  gl_FragColor = vec4(0.25 + 0.5 * vec3(c[0].x, c[1].x, c[2].x), 1.0);
}`,
  });
  const scene = new THREE.Scene();
  scene.add(new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material));
  renderer.setSize(width * scale, height * scale, false);
  renderer.render(scene, new THREE.Camera());
  const gl = renderer.getContext();
  const out = new Uint8Array(width * scale * height * scale * 4);
  gl.readPixels(0, 0, width * scale, height * scale, gl.RGBA, gl.UNSIGNED_BYTE, out);
  material.dispose();
  texture.dispose();
  return Array.from(out);
};
window.ptmReadsPageReady = true;
