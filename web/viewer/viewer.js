// texlume viewer: a PTM-textured model relit per fragment (docs/viewer.md).
// The page is served by `texlume view`, which prepares /model/scene.json,
// /model/geometry.bin and the PTM of every atlas as 8-bit RGBA PNGs.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { ptmReadsGlsl } from './ptm_reads.js';
import { colmapProjection, worldFromColmapCamera } from './colmap_camera.js';

const statusEl = document.getElementById('status');
let canvas = document.getElementById('view');  // replaced by makeRenderer on a GPU
// Times (ms since the page was opened) at each step of loading, for the bench.
const api = { ready: false, errors: [], firstFrameMs: null, marks: { moduleStart: performance.now() } };
window.texlumeViewer = api;

// What the vertex shader hands to the fragment shader.
const varyings = /* glsl */ `
varying vec2 vUv;
varying vec3 vNormal;
varying vec3 vFaceNormal;
varying vec3 vTangent;
varying vec3 vBarycentric;
varying float vChart;
varying vec3 vWorldPosition;
`;

const vertexShader = /* glsl */ `
attribute vec3 ptmTangent;
attribute vec3 faceNormal;
attribute vec3 barycentric;
attribute float chartId;
${varyings}
void main() {
  vUv = uv;
  vNormal = normalize(mat3(modelMatrix) * normal);
  vFaceNormal = normalize(mat3(modelMatrix) * faceNormal);
  vTangent = normalize(mat3(modelMatrix) * ptmTangent);
  vBarycentric = barycentric;
  vChart = chartId;
  vec4 world = modelMatrix * vec4(position, 1.0);
  vWorldPosition = world.xyz;
  gl_Position = projectionMatrix * viewMatrix * world;
}`;

const fragmentShader = /* glsl */ `
precision highp float;
uniform sampler2D bakedTexture;
uniform int mode;            // 0 PTM, 1 baked 2D texture, 2 flat
uniform bool showSeams, showCharts;
uniform float specular;      // ks of the specular enhancement, 0 = off
uniform vec3 lightWorld;     // unit vector towards the light
uniform vec3 flatAlbedo;     // display domain
uniform float horizonZ;      // sin of the horizon elevation (PTM evaluation)
uniform float responseFactor[10];  // light response: factor per 10 degrees of elevation
uniform float ambient;       // light response: ambient times the zenith value (linear)
uniform float orenNayarBOverA;  // light response: the view's term (Oren and Nayar's B / A)
uniform sampler2D horizon0, horizon1, horizon2, horizon3;  // the relief's horizon, 16 sectors
uniform bool hasHorizon;
uniform float horizonScale;  // radians per unit of a horizon texture's value
uniform float shadowFloor;   // linear fraction of the light a shadow keeps
uniform float penumbra;      // radians across which the light rises from shadow
${varyings}
float srgbToLinear(float v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }
vec3 srgbToLinear(vec3 v) { return vec3(srgbToLinear(v.r), srgbToLinear(v.g), srgbToLinear(v.b)); }
float linearToSrgb(float v) {
  v = max(v, 0.0);
  return v <= 0.0031308 ? v * 12.92 : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}
vec3 linearToSrgb(vec3 v) { return vec3(linearToSrgb(v.r), linearToSrgb(v.g), linearToSrgb(v.b)); }

${ptmReadsGlsl}
// Paper 003 eq. 1: L = a0 lu^2 + a1 lv^2 + a2 lu lv + a3 lu + a4 lv + a5.
float biquadratic(vec3 a012, vec3 a345, vec2 l) {
  return a012.x * l.x * l.x + a012.y * l.y * l.y + a012.z * l.x * l.y + a345.x * l.x +
         a345.y * l.y + a345.z;
}

// The luminance coefficients (LRGB: its own, up to the colour's scale, which
// does not move the maximum; RGB: the channels' mean).
void luminance(vec3 c[6], out vec3 a012, out vec3 a345) {
  const vec3 third = vec3(1.0 / 3.0);
  a012 = vec3(dot(c[0], third), dot(c[1], third), dot(c[2], third));
  a345 = vec3(dot(c[3], third), dot(c[4], third), dot(c[5], third));
}

// The PTM's RGB (display domain) for a light l in the texel frame (eqs. 1-2;
// LRGB: the luminance times the colour).
vec3 evaluate(vec3 c[6], vec3 colour, vec2 l) {
  return (c[0] * l.x * l.x + c[1] * l.y * l.y + c[2] * l.x * l.y + c[3] * l.x + c[4] * l.y + c[5]) *
         colour;
}

// The light response's factor at a light's l_z: linear in the elevation
// between knots every 10 degrees (docs/synth.md, "Light response").
float responseAt(float lz) {
  float k = clamp(degrees(asin(clamp(lz, 0.0, 1.0))) / 10.0, 0.0, 9.0);
  int i = int(min(floor(k), 8.0));
  float f = k - float(i);
  float lo = 1.0, hi = 1.0;
  for (int j = 0; j < 9; ++j) {  // constant-index access (GLSL ES 1.0)
    if (j == i) { lo = responseFactor[j]; hi = responseFactor[j + 1]; }
  }
  return mix(lo, hi, f);
}

// Oren and Nayar's view term max(0, cos(phi_r - phi_i)) sin(alpha) tan(beta) for the
// light l and the view v in the texel frame, beta at most 80 degrees
// (ptm::OrenNayarTerm).
float orenNayarTerm(vec3 l, vec3 v) {
  if (l.z <= 0.0 || v.z <= 0.0) return 0.0;
  float ll = length(l.xy), lv = length(v.xy);
  if (ll < 1e-12 || lv < 1e-12) return 0.0;
  float cosAzimuth = dot(l.xy, v.xy) / (ll * lv);
  if (cosAzimuth <= 0.0) return 0.0;
  float thetaI = acos(min(1.0, l.z)), thetaR = acos(min(1.0, v.z));
  return cosAzimuth * sin(max(thetaI, thetaR)) * tan(min(min(thetaI, thetaR), radians(80.0)));
}

// The relief's self-shadowing of the light l (texel frame), as texlume's renderer
// (ptm::SelfShadowing::LightFactor): the horizon at l's azimuth, linear between
// the two nearest of 16 sectors, and v + (1 - v) shadowFloor, v rising linearly
// across the penumbra about it.
float shadowFactor(vec3 l) {
  if (!hasHorizon) return 1.0;
  vec4 h0 = texture2D(horizon0, vUv), h1 = texture2D(horizon1, vUv);
  vec4 h2 = texture2D(horizon2, vUv), h3 = texture2D(horizon3, vUv);
  // atan(0, 0) is undefined in GLSL: a light along the normal takes azimuth 0, as atan2 does.
  float azimuth = length(l.xy) > 1e-6 ? atan(l.y, l.x) : 0.0;
  float at = mod(azimuth / 6.2831853 * 16.0, 16.0);
  int i = int(min(floor(at), 15.0));
  float f = at - float(i);
  float lo = 0.0, hi = 0.0;
  for (int j = 0; j < 16; ++j) {  // constant-index access (GLSL ES 1.0)
    vec4 h = j < 4 ? h0 : j < 8 ? h1 : j < 12 ? h2 : h3;
    int c = j - 4 * (j / 4);
    float e = c == 0 ? h.x : c == 1 ? h.y : c == 2 ? h.z : h.w;
    if (j == i) lo = e;
    if (j == i + 1 || (i == 15 && j == 0)) hi = e;
  }
  float horizon = mix(lo, hi, f) * horizonScale;
  float v = clamp((asin(clamp(l.z, -1.0, 1.0)) - horizon) / penumbra + 0.5, 0.0, 1.0);
  return v + (1.0 - v) * shadowFloor;
}

// As texlume's renderer: lights below the horizon elevation are evaluated at it
// (same azimuth), fading linearly with l_z to 0 at the horizon; the light
// response's factors (elevation, and the view v's) and ambient term apply
// (ptm::EffectiveLights).
vec3 relight(vec3 c[6], vec3 colour, vec3 l, vec3 v) {
  vec3 linear = ambient * srgbToLinear(max(evaluate(c, colour, vec2(0.0)), vec3(0.0)));
  if (l.z <= 0.0) return linearToSrgb(linear);
  float fall = responseAt(l.z) * (1.0 + orenNayarBOverA * orenNayarTerm(l, v)) * shadowFactor(l);
  vec3 at = l;
  if (l.z < horizonZ) {
    fall *= l.z / horizonZ;
    float r = max(length(l.xy), 1e-6);
    at = vec3(l.xy * sqrt(1.0 - horizonZ * horizonZ) / r, horizonZ);
  }
  return linearToSrgb(linear + srgbToLinear(max(evaluate(c, colour, at.xy), vec3(0.0))) * fall);
}

// The direction of the biquadratic's maximum (Malzbender et al. 2001, eq. 16).
vec3 ptmNormal(vec3 c[6]) {
  vec3 a012, a345;
  luminance(c, a012, a345);
  float det = 4.0 * a012.x * a012.y - a012.z * a012.z;
  vec2 n;
  if (abs(det) < 1e-12 || !(a012.x < 0.0 && det > 0.0)) {
    n = a345.xy;
    float len = length(n);
    if (len < 1e-12) return vec3(0.0, 0.0, 1.0);
    n = n / max(len, 1.0) * min(1.0, len);
  } else {
    n = vec2(a012.z * a345.y - 2.0 * a012.y * a345.x, a012.z * a345.x - 2.0 * a012.x * a345.y) / det;
    if (dot(n, n) > 1.0) n = normalize(n);
  }
  return vec3(n, sqrt(max(0.0, 1.0 - dot(n, n))));
}

vec3 chartColour(float id) {
  return 0.5 + 0.5 * cos(6.2831853 * (fract(id * 0.618034) + vec3(0.0, 0.33, 0.67)));
}

// x turned by the smallest rotation that takes the unit vector a to the unit vector b
// (Rodrigues; a and b are never opposite: a face normal and a vertex normal of it).
vec3 turned(vec3 x, vec3 a, vec3 b) {
  vec3 axis = cross(a, b);
  float c = dot(a, b);
  return x * c + cross(axis, x) + axis * (dot(axis, x) / max(1.0 + c, 1e-6));
}

void main() {
  // The atlas frame of the face turned so that its z is the interpolated vertex
  // normal: shading varies smoothly across the coarse mesh's faces, per fragment,
  // as in texlume's renderer (render/model_render.cpp).
  vec3 n = normalize(vNormal);
  vec3 t = normalize(turned(normalize(vTangent), normalize(vFaceNormal), n));
  t = normalize(t - n * dot(n, t));
  vec3 b = cross(n, t);  // the atlas frame's y (v up)
  vec3 l = vec3(dot(lightWorld, t), dot(lightWorld, b), dot(lightWorld, n));
  vec3 toEye = normalize(cameraPosition - vWorldPosition);
  vec3 v = vec3(dot(toEye, t), dot(toEye, b), dot(toEye, n));
  vec3 colour;
  if (mode == 0) {
    vec3 c[6], tint;
    ptmValues(c, tint);  // sampled once per fragment
    colour = relight(c, tint, l, v);
    if (specular > 0.0 && l.z > 0.0) {
      vec3 h = normalize(l + v);
      colour += specular * pow(max(dot(ptmNormal(c), h), 0.0), 40.0);
    }
  } else if (mode == 1) {
    colour = texture2D(bakedTexture, vUv).rgb;
  } else {
    colour = linearToSrgb(srgbToLinear(flatAlbedo) * max(l.z, 0.0));
  }
  if (showCharts) colour = mix(colour, chartColour(vChart), 0.45);
  if (showSeams) {
    float d = min(vBarycentric.x, min(vBarycentric.y, vBarycentric.z));
    float line = 1.0 - smoothstep(0.0, 1.5 * fwidth(d), d);
    colour = mix(colour, vec3(1.0, 0.85, 0.1), line);
  }
  gl_FragColor = vec4(clamp(colour, 0.0, 1.0), 1.0);
}`;

function fail(message) {
  statusEl.textContent = message;
  statusEl.className = 'error';
  api.errors.push(message);
  console.error(message);
}

// A texture of raw values from a decoded PNG (prefetch.js flipped it already).
function textureOf(bitmap) {
  const texture = new THREE.Texture(bitmap);
  texture.flipY = false;                    // flipped while decoding
  texture.colorSpace = THREE.NoColorSpace;  // raw values: coefficients, display-domain colour
  texture.minFilter = THREE.LinearFilter;   // no mipmaps: gutters cover the 4 x 4 taps only
  texture.magFilter = THREE.LinearFilter;
  texture.generateMipmaps = false;
  texture.needsUpdate = true;
  return texture;
}

// The page's WebGL renderer. Multisampling costs a CPU rasteriser (SwiftShader,
// llvmpipe) about half its frame rate and a GPU next to nothing: the canvas's
// first context, made without it, is kept on a software rasteriser; on a GPU the
// page draws on a fresh canvas (a canvas keeps its first context's settings)
// with multisampling.
function makeRenderer() {
  const settings = { alpha: false, depth: true, stencil: false, premultipliedAlpha: true, preserveDrawingBuffer: true };
  const gl = canvas.getContext('webgl2', { ...settings, antialias: false });
  if (gl) {
    const info = gl.getExtension('WEBGL_debug_renderer_info');
    const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    if (/swiftshader|llvmpipe|softpipe|software/i.test(name))
      return { renderer: new THREE.WebGLRenderer({ canvas, context: gl, ...settings, antialias: false }), software: true };
    const lose = gl.getExtension('WEBGL_lose_context');
    if (lose) lose.loseContext();
    const fresh = canvas.cloneNode(false);
    canvas.replaceWith(fresh);
    canvas = fresh;
  }
  return { renderer: new THREE.WebGLRenderer({ canvas, ...settings, antialias: true }), software: false };
}

async function main() {
  // prefetch.js started fetching the model and decoding its PTM textures.
  const prefetch = window.texlumePrefetch;
  if (!prefetch) throw new Error('/viewer/prefetch.js did not run');
  api.marks.prefetchStart = prefetch.started;
  const scene = await prefetch.scene;
  if (scene.format !== 'texlume-web-3') throw new Error('scene.json: unknown format ' + scene.format);
  api.marks.scene = performance.now();
  const bytes = await prefetch.geometry;
  api.marks.geometry = performance.now();
  const g = scene.geometry;
  const attribute = (name) => {
    const a = g.attributes[name];
    return new Float32Array(bytes, a.byte_offset, g.vertices * a.components);
  };
  const position = attribute('position'), normal = attribute('normal'),
        faceNormal = attribute('face_normal'), tangent = attribute('tangent'), uv = attribute('uv'),
        chart = attribute('chart');
  const barycentric = new Float32Array(g.vertices * 3);
  for (let v = 0; v < g.vertices; ++v) barycentric[v * 3 + (v % 3)] = 1;

  const { renderer, software } = makeRenderer();
  api.softwareRenderer = software;
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;  // shaders write display values as they are
  const world = new THREE.Scene();
  world.background = new THREE.Color().setRGB(32 / 255, 33 / 255, 36 / 255, THREE.LinearSRGBColorSpace);
  // Stands in for the textures until they are in: RGBA8 and filtered as they are.
  const placeholder = new THREE.DataTexture(new Uint8Array([128, 128, 128, 255]), 1, 1);
  placeholder.minFilter = placeholder.magFilter = THREE.LinearFilter;
  placeholder.needsUpdate = true;
  const uniformsShared = {
    lightWorld: { value: new THREE.Vector3(0, 0, 1) },
    mode: { value: 0 },
    showSeams: { value: false },
    showCharts: { value: false },
    specular: { value: 0 },
    flatAlbedo: { value: new THREE.Vector3(...scene.flat_albedo) },
    horizonZ: { value: Math.sin(scene.horizon_elevation_deg * Math.PI / 180) },
    // A scene.json without one (written before it): the identity.
    responseFactor: { value: scene.light_response ? scene.light_response.factors : Array(10).fill(1) },
    ambient: { value: scene.light_response ? scene.light_response.ambient : 0 },
    orenNayarBOverA: {
      value: scene.light_response ? scene.light_response.oren_nayar_b_over_a || 0 : 0,
    },
  };
  const materials = [];
  for (const range of g.ranges) {
    const atlas = scene.atlases[range.atlas];
    const scale = [], bias = [];
    for (let k = 0; k < 5; ++k) {
      const t = atlas.textures[Math.min(k, atlas.textures.length - 1)];
      const four = (v, fill) => new THREE.Vector4(...[0, 1, 2, 3].map((i) => (i < v.length ? v[i] : fill)));
      scale.push(four(t.scale, 0));
      bias.push(four(t.bias, 0));
    }
    const uniforms = { ...uniformsShared, lrgb: { value: atlas.format === 'LRGB' },
      ptmScale: { value: scale }, ptmBias: { value: bias }, bakedTexture: { value: placeholder },
      ptmSize: { value: new THREE.Vector2(1, 1) },  // the placeholder's; the atlas's once in
      hasHorizon: { value: false },  // until its textures are in
      horizonScale: { value: atlas.horizon ? atlas.horizon.elevation_scale : 0 },
      shadowFloor: { value: atlas.horizon ? atlas.horizon.shadow_floor : 1 },
      penumbra: { value: atlas.horizon ? atlas.horizon.penumbra_rad : 1 } };
    for (let k = 0; k < 5; ++k) uniforms['ptm' + k] = { value: placeholder };  // until they are in
    for (let k = 0; k < 4; ++k) uniforms['horizon' + k] = { value: placeholder };
    const material = new THREE.ShaderMaterial({ uniforms, vertexShader, fragmentShader });
    materials.push(material);
    const geometry = new THREE.BufferGeometry();
    const slice = (array, components) => new THREE.BufferAttribute(
        array.subarray(range.first_vertex * components, (range.first_vertex + range.vertices) * components),
        components);
    geometry.setAttribute('position', slice(position, 3));
    geometry.setAttribute('normal', slice(normal, 3));
    geometry.setAttribute('faceNormal', slice(faceNormal, 3));
    geometry.setAttribute('ptmTangent', slice(tangent, 3));
    geometry.setAttribute('uv', slice(uv, 2));
    geometry.setAttribute('chartId', slice(chart, 1));
    geometry.setAttribute('barycentric', slice(barycentric, 3));
    geometry.computeBoundingSphere();
    world.add(new THREE.Mesh(geometry, material));
  }

  const lo = new THREE.Vector3(...scene.bounds.min), hi = new THREE.Vector3(...scene.bounds.max);
  const centre = lo.clone().add(hi).multiplyScalar(0.5);
  const radius = Math.max(hi.clone().sub(lo).length() * 0.5, 1e-6);
  const camera = new THREE.PerspectiveCamera(35, 1, radius * 0.01, radius * 100);
  camera.position.copy(centre).add(new THREE.Vector3(0, 0, radius * 3.2));
  const controls = new OrbitControls(camera, canvas);
  controls.target.copy(centre);
  controls.update();

  // The light is held in the camera's frame (x right, y up, z towards the viewer),
  // as on an RTI viewer's light sphere, so it stays put while the model turns.
  const lightView = new THREE.Vector3(-0.5, 0.5, Math.sqrt(0.5));
  // A COLMAP camera and a light in the world, when set (setView): what `texlume render`
  // draws for that image and light.
  let colmapView = null;
  const render = () => {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) ||
        canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
      renderer.setSize(w, h, false);
      camera.aspect = w / Math.max(h, 1);
      camera.updateProjectionMatrix();
    }
    if (colmapView) {
      camera.projectionMatrix.copy(colmapView.projection);
      camera.projectionMatrixInverse.copy(colmapView.projection).invert();
      uniformsShared.lightWorld.value.copy(colmapView.lightWorld);
    } else {
      uniformsShared.lightWorld.value.copy(lightView).applyQuaternion(camera.quaternion).normalize();
    }
    renderer.render(world, camera);
  };
  // A pinhole camera as COLMAP gives it (cam_from_world: qvec w, x, y, z and tvec;
  // fx, fy, cx, cy in pixels of a width x height image, pixel centres at +0.5) and a
  // unit light direction in the world. COLMAP's camera looks along +z with y down;
  // three.js's along -z with y up.
  const setView = (c, lightWorld) => {
    worldFromColmapCamera(c).decompose(camera.position, camera.quaternion, camera.scale);
    camera.updateMatrixWorld();
    const projection = colmapProjection(c, camera.near, camera.far);
    colmapView = { projection, lightWorld: new THREE.Vector3(...lightWorld).normalize() };
    render();
  };
  let pending = false;
  const requestRender = () => {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => { pending = false; render(); });
  };
  controls.addEventListener('change', requestRender);
  window.addEventListener('resize', requestRender);

  // Light sphere: drag to set the light direction.
  const lightCanvas = document.getElementById('light');
  const lightValue = document.getElementById('light-value');
  const drawLightSphere = () => {
    const c = lightCanvas.getContext('2d');
    const r = lightCanvas.width / 2 - 2;
    c.clearRect(0, 0, lightCanvas.width, lightCanvas.height);
    const grad = c.createRadialGradient(r + 2 + lightView.x * r, r + 2 - lightView.y * r, 2, r + 2, r + 2, r * 1.4);
    grad.addColorStop(0, '#f1f3f4');
    grad.addColorStop(1, '#3c4043');
    c.fillStyle = grad;
    c.beginPath();
    c.arc(r + 2, r + 2, r, 0, 2 * Math.PI);
    c.fill();
    c.fillStyle = '#fbbc04';
    c.beginPath();
    c.arc(r + 2 + lightView.x * r, r + 2 - lightView.y * r, 4, 0, 2 * Math.PI);
    c.fill();
    lightValue.textContent = `(${lightView.x.toFixed(2)}, ${lightView.y.toFixed(2)}, ${lightView.z.toFixed(2)})`;
  };
  const setLight = (x, y, z) => {
    lightView.set(x, y, z);
    if (lightView.lengthSq() === 0) lightView.set(0, 0, 1);
    lightView.normalize();
    drawLightSphere();
    requestRender();
  };
  const lightFromPointer = (event) => {
    const rect = lightCanvas.getBoundingClientRect();
    let x = ((event.clientX - rect.left) / rect.width) * 2 - 1;
    let y = 1 - ((event.clientY - rect.top) / rect.height) * 2;
    const d = Math.hypot(x, y);
    if (d > 1) { x /= d; y /= d; }
    setLight(x, y, Math.sqrt(Math.max(0, 1 - x * x - y * y)));
  };
  lightCanvas.addEventListener('pointerdown', (e) => {
    lightCanvas.setPointerCapture(e.pointerId);
    lightFromPointer(e);
  });
  lightCanvas.addEventListener('pointermove', (e) => {
    if (lightCanvas.hasPointerCapture(e.pointerId)) lightFromPointer(e);
  });

  for (const input of document.querySelectorAll('input[name=mode]')) {
    input.addEventListener('change', () => {
      uniformsShared.mode.value = { ptm: 0, baked: 1, flat: 2 }[input.value];
      requestRender();
    });
  }
  const toggle = (id, uniform, on) => document.getElementById(id).addEventListener('change', (e) => {
    uniformsShared[uniform].value = e.target.checked ? on : (typeof on === 'number' ? 0 : false);
    requestRender();
  });
  toggle('seams', 'showSeams', true);
  toggle('charts', 'showCharts', true);
  toggle('specular', 'specular', 0.6);

  const texturesOfAtlas = await prefetch.ptmTextures;
  const horizonsOfAtlas = await prefetch.horizonTextures;
  const ptmTextures = [], horizonTextures = [];  // per atlas
  await Promise.all(g.ranges.map(async (range, i) => {
    const bitmaps = await texturesOfAtlas[range.atlas];
    const u = materials[i].uniforms;
    ptmTextures[range.atlas] = ptmTextures[range.atlas] || bitmaps.map(textureOf);
    for (let k = 0; k < bitmaps.length; ++k) u['ptm' + k].value = ptmTextures[range.atlas][k];
    u.ptmSize.value.set(bitmaps[0].width, bitmaps[0].height);
    const horizon = await horizonsOfAtlas[range.atlas];
    if (horizon.length === 4) {
      horizonTextures[range.atlas] = horizonTextures[range.atlas] || horizon.map(textureOf);
      for (let k = 0; k < 4; ++k) u['horizon' + k].value = horizonTextures[range.atlas][k];
      u.hasHorizon.value = true;
    }
  }));
  api.marks.textures = performance.now();
  renderer.compile(world, camera);
  api.marks.compiled = performance.now();
  for (const material of materials)
    for (const u of Object.values(material.uniforms))
      if (u.value && u.value.isTexture) renderer.initTexture(u.value);
  api.marks.uploaded = performance.now();
  drawLightSphere();
  render();
  // Since the page was opened (navigation start): HTML, scripts, model, first frame.
  api.firstFrameMs = performance.now();
  statusEl.textContent = `${scene.faces} triangles, ${scene.atlases.length} atlas(es), ` +
      `${scene.charts} charts; first frame after ${(api.firstFrameMs / 1000).toFixed(2)} s` +
      (api.softwareRenderer ? ' (software WebGL: no multisampling)' : '');
  Object.assign(api, {
    setLight,
    setView,
    renderNow: render,
    // Blocks until the GPU has drawn everything (reads a pixel back; for timing frames).
    finish: () => {
      const gl = renderer.getContext();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    },
    faces: scene.faces,
    // The bytes of PTM texture k of an atlas as WebGL holds them, w x h texels
    // from (x, y), rows from v = 0 up (for the tests: nothing may be lost on the
    // way, the alpha channel included).
    ptmTextureBytes: (atlas, k, x, y, w, h) => {
      const gl = renderer.getContext();
      const framebuffer = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, framebuffer);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D,
          renderer.properties.get(ptmTextures[atlas][k]).__webglTexture, 0);
      const bytes = new Uint8Array(w * h * 4);
      gl.readPixels(x, y, w, h, gl.RGBA, gl.UNSIGNED_BYTE, bytes);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.deleteFramebuffer(framebuffer);
      return Array.from(bytes);
    },
  });
  // The baked 2D textures are only needed for the baked mode: loaded after the
  // first frame; `ready` once they are in.
  const baked = await Promise.all(scene.atlases.map((atlas) => {
    const name = atlas.baked || atlas.base_colour;
    return name ? prefetch.decode(name).then(textureOf) : placeholder;
  }));
  g.ranges.forEach((range, i) => { materials[i].uniforms.bakedTexture.value = baked[range.atlas]; });
  requestRender();
  api.marks.baked = performance.now();
  api.ready = true;
}

main().catch((e) => fail('texlume viewer: ' + e.message));
