// A plain glTF viewer for the browser tests (web/test/viewer.test.mjs): three.js's own GLTFLoader and
// MeshStandardMaterial, nothing of texlume's. Bundled by the test with esbuild.
// window.drawGlb(url, camera, lightWorld, { normalMap }) draws model.glb through a
// COLMAP pinhole camera of the model's frame under a directional light (a direction
// in the model's frame), both moved into glTF's frame by the node's matrix;
// flipGreen reads the normal map's green the other way (DirectX's convention).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { colmapProjection, worldFromColmapCamera } from '../viewer/colmap_camera.js';

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
renderer.outputColorSpace = THREE.SRGBColorSpace;
let loaded = null;

window.drawGlb = async (url, c, lightInModel, { normalMap = true, flipGreen = false } = {}) => {
  if (!loaded) loaded = await new GLTFLoader().loadAsync(url);
  const root = loaded.scene;
  root.updateMatrixWorld(true);
  const node = root.getObjectByName('model');
  const gltfFromModel = node.matrixWorld.clone();
  root.traverse((o) => {
    if (!o.isMesh) return;
    o.material.userData.normalMap ??= o.material.normalMap;
    o.material.normalMap = normalMap ? o.material.userData.normalMap : null;
    o.material.normalScale.set(1, flipGreen ? -1 : 1);  // flipped: the other (DirectX) convention
    o.material.needsUpdate = true;
  });
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0, 0, 0);
  scene.add(root);
  // Lambert's albedo x n.l: three's diffuse BRDF is albedo / pi under irradiance I n.l.
  const light = new THREE.DirectionalLight(0xffffff, Math.PI);
  light.position.copy(new THREE.Vector3(...lightInModel).transformDirection(gltfFromModel));
  scene.add(light);
  // COLMAP's camera in the model's frame, moved into glTF's frame.
  const camera = new THREE.PerspectiveCamera();
  camera.matrixAutoUpdate = false;
  camera.matrix.copy(gltfFromModel).multiply(worldFromColmapCamera(c));
  camera.matrixWorld.copy(camera.matrix);
  camera.matrixWorldInverse.copy(camera.matrix).invert();
  camera.projectionMatrix.copy(colmapProjection(c, 0.01, 100));
  camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
  renderer.setSize(c.width, c.height, false);
  renderer.render(scene, camera);
  return { tangents: !!loaded.scene.getObjectByProperty('isMesh', true).geometry.attributes.tangent };
};
window.glbPageReady = true;
