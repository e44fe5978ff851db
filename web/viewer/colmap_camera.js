// COLMAP's pinhole camera in three.js: the viewer's setView and the browser tests' plain
// glTF page (web/test_pages/glb_page.js) draw through the same camera.
import * as THREE from 'three';

// The camera's matrix (world from camera, three.js's convention) of a COLMAP image:
// cam_from_world is qvec (w, x, y, z) and tvec. COLMAP's camera looks along +z with y
// down, three.js's along -z with y up: a half turn about the camera's x between them.
export function worldFromColmapCamera(c) {
  const camFromWorld = new THREE.Quaternion(c.qvec[1], c.qvec[2], c.qvec[3], c.qvec[0]).normalize();
  const worldFromCam = camFromWorld.clone().invert();
  const centre = new THREE.Vector3(...c.tvec).applyQuaternion(worldFromCam).multiplyScalar(-1);
  const turned = worldFromCam.clone().multiply(new THREE.Quaternion(1, 0, 0, 0));
  return new THREE.Matrix4().compose(centre, turned, new THREE.Vector3(1, 1, 1));
}

// The projection of a pinhole camera (fx, fy, cx, cy in pixels of a width x height
// image, pixel centres at +0.5) with near and far planes at `near` and `far`.
export function colmapProjection(c, near, far) {
  const n = near, f = far;
  return new THREE.Matrix4().set(
      2 * c.fx / c.width, 0, 1 - 2 * c.cx / c.width, 0,
      0, 2 * c.fy / c.height, 2 * c.cy / c.height - 1, 0,
      0, 0, -(f + n) / (f - n), -2 * f * n / (f - n),
      0, 0, -1, 0);
}
