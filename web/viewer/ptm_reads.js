// The viewer's PTM atlas reads in GLSL (ES 1.0): the atlas's planes at the fragment,
// read Catmull-Rom, as texlume's renderer reads an atlas (core/cubic_interpolation.h,
// CatmullRomTaps), so the two draw the same picture and neither flattens the finest
// detail the atlas holds (issue 29). The fragment shader that includes it declares
// `varying vec2 vUv` first. Used by viewer.js and by the browser test that checks it
// (web/test_pages/ptm_reads_page.js).
export const ptmReadsGlsl = /* glsl */ `
uniform sampler2D ptm0, ptm1, ptm2, ptm3, ptm4;
uniform vec4 ptmScale[5];
uniform vec4 ptmBias[5];
uniform vec2 ptmSize;        // the PTM textures' width and height, texels
uniform bool lrgb;

// Catmull-Rom weights of the taps floor(x) - 1 .. floor(x) + 2 around a point t
// past floor(x) (Keys 1981, a = -1/2).
vec4 catmullRomWeights(float t) {
  float t2 = t * t, t3 = t2 * t;
  return vec4(-0.5 * t3 + t2 - 0.5 * t, 1.5 * t3 - 2.5 * t2 + 1.0,
              -1.5 * t3 + 2.0 * t2 + 0.5 * t, 0.5 * t3 - 0.5 * t2);
}

// The Catmull-Rom taps at uv of textures of size texels (bilinear filter, clamped to
// their edges), over the 4 x 4 texels around, the point clamped to the texel centres.
// The two middle taps of each axis have positive weights, so one bilinear read at
// w2 / (w1 + w2) past the first of them gives both: 9 reads instead of 16 (the taps
// beyond an edge read the edge texel, as the sampler clamps). Built once per fragment
// and read from every PTM texture, as CatmullRomTaps is in the renderer.
struct CatmullRomTaps {
  vec2 at0, at12, at3;   // texture coordinates of the first, middle and last reads
  vec4 wx, wy;           // the 4 weights of each axis
  vec2 w12;              // the middle taps' weight sums, at least 1
};

CatmullRomTaps catmullRomTaps(vec2 uv, vec2 size) {
  vec2 p = clamp(uv * size - 0.5, vec2(0.0), size - 1.0);
  vec2 base = floor(p);
  CatmullRomTaps taps;
  taps.wx = catmullRomWeights(p.x - base.x);
  taps.wy = catmullRomWeights(p.y - base.y);
  taps.w12 = vec2(taps.wx.y + taps.wx.z, taps.wy.y + taps.wy.z);
  taps.at0 = (base - 0.5) / size;
  taps.at3 = (base + 2.5) / size;
  taps.at12 = (base + 0.5 + vec2(taps.wx.z, taps.wy.z) / taps.w12) / size;
  return taps;
}

// One row of reads at texture row y.
vec4 catmullRomRow(sampler2D t, CatmullRomTaps taps, float y) {
  return taps.wx.x * texture2D(t, vec2(taps.at0.x, y)) +
         taps.w12.x * texture2D(t, vec2(taps.at12.x, y)) + taps.wx.w * texture2D(t, vec2(taps.at3.x, y));
}

// Texture t read at the taps.
vec4 catmullRom(sampler2D t, CatmullRomTaps taps) {
  return taps.wy.x * catmullRomRow(t, taps, taps.at0.y) +
         taps.w12.y * catmullRomRow(t, taps, taps.at12.y) + taps.wy.w * catmullRomRow(t, taps, taps.at3.y);
}

// Texture k of the atlas: four 8-bit values times scale plus bias (docs/viewer.md).
vec4 ptmTexel(sampler2D t, CatmullRomTaps taps, int k) {
  return catmullRom(t, taps) * ptmScale[k] + ptmBias[k];
}

// The PTM's values at this fragment: LRGB, the luminance coefficients a0..a5 in
// c[0].x, c[1].x, ..., and the colour in colour; RGB, coefficient k of the R, G,
// B polynomials in c[k].
void ptmValues(out vec3 c[6], out vec3 colour) {
  CatmullRomTaps taps = catmullRomTaps(vUv, ptmSize);
  vec4 t0 = ptmTexel(ptm0, taps, 0), t1 = ptmTexel(ptm1, taps, 1);
  if (lrgb) {
    c[0] = vec3(t0.x); c[1] = vec3(t0.y); c[2] = vec3(t0.z);
    c[3] = vec3(t0.w); c[4] = vec3(t1.x); c[5] = vec3(t1.y);
    colour = vec3(t1.z, t1.w, 3.0 - t1.z - t1.w);  // the colour sums to 3
    return;
  }
  vec4 t2 = ptmTexel(ptm2, taps, 2), t3 = ptmTexel(ptm3, taps, 3), t4 = ptmTexel(ptm4, taps, 4);
  c[0] = t0.xyz; c[1] = vec3(t0.w, t1.xy); c[2] = vec3(t1.zw, t2.x);
  c[3] = t2.yzw; c[4] = t3.xyz; c[5] = vec3(t3.w, t4.xy);
  colour = vec3(1.0);
}
`;
