// Draws a small RGBA8 texture magnified through the viewer's own Catmull-Rom read
// (web/viewer/catmull_rom.js), for the browser tests (web/test/viewer.test.mjs).
// Bundled by the test with esbuild. window.drawCatmullRom(bytes, width, height,
// scale) returns the picture's RGBA bytes, rows from the bottom (texture row 0) up;
// each pixel shows 0.25 + 0.5 x the read, so the filter's overshoot stays in range.
import * as THREE from 'three';
import { catmullRomGlsl } from '../viewer/catmull_rom.js';

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;  // values as they are

window.drawCatmullRom = (bytes, width, height, scale) => {
  const texture = new THREE.DataTexture(new Uint8Array(bytes), width, height);
  texture.minFilter = texture.magFilter = THREE.LinearFilter;  // as the viewer's atlases
  texture.generateMipmaps = false;
  texture.needsUpdate = true;
  const material = new THREE.ShaderMaterial({
    uniforms: { t: { value: texture }, size: { value: new THREE.Vector2(width, height) } },
    vertexShader: 'varying vec2 vUv;\nvoid main() { vUv = uv; gl_Position = vec4(position.xy, 0.0, 1.0); }',
    fragmentShader: `precision highp float;
uniform sampler2D t;
uniform vec2 size;
varying vec2 vUv;
${catmullRomGlsl}
void main() { gl_FragColor = vec4(0.25 + 0.5 * catmullRom(t, vUv, size).rgb, 1.0); }`,
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
window.catmullRomPageReady = true;
