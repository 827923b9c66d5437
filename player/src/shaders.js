// The player's GLSL (WebGL 2): the pre-lit pass relights each view's texels by an L2
// light (the SH transfer) and a sun (normals and albedo); the hull pass gives each pixel
// of the frame its ray's distance to the pose's hull mesh (the proxy); the frame pass
// re-bins each pixel's ray through the cylinder of camera centres and morphs the quad's
// pre-lit views by the solved four-way morph. Twins, operation for operation, of frf's
// `shaders/relight.wgsl` (the SH part: `reflectance/src/sh_transfer.rs`),
// `shaders/rebin.wgsl`, `shaders/common.wgsl`, `shaders/rebin/*.wgsl` and
// `shaders/morph/solved.wgsl`, whose comments and docs/design.md derive them.

export const FULLSCREEN_VERTEX = /* glsl */ `
precision highp float;
in vec3 position;
void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }
`;

/**
 * The pre-lit pass: one view's texels (layer uLayer) relit by the L2 light and up to
 * MAX_SUNS (4) suns, each relit sharply.
 */
export const PRELIT_FRAGMENT = /* glsl */ `
precision highp float;
precision highp int;
precision highp sampler2DArray;
#define MAX_SUNS 4
uniform sampler2DArray uAtlas;    // R8: layer 3 * view + channel (compact: 1 per view); packed: RGB, layer view
uniform int uAtlasPacked;         // 1: a KTX2 atlas, a view's channels in one layer's RGB
uniform int uBasisPacked;         // 1: the basis likewise
uniform sampler2DArray uAlpha;    // R8
uniform sampler2DArray uNormals;  // RGBA8: n = 2 rgb - 1, a = 0 where none
uniform sampler2DArray uAlbedo;   // RGBA8 (rgb) of the albedo, and of the compact colour
uniform int uLayer;
uniform int uCompact;
uniform vec3 uScale[9];
uniform vec3 uOffset[9];
uniform vec3 uSh[9];              // the light's radiance coefficients (three.js order)
uniform vec3 uAlbedoScale;
uniform vec3 uColourScale;
uniform int uSunCount;            // suns relit sharply (0: none)
uniform vec3 uSunDirs[MAX_SUNS];  // toward each sun, subject frame
uniform vec3 uSunEs[MAX_SUNS];    // their illuminance
uniform int uHasNormals;
// A sun's shadow (frf's SunLight::sunlit): each texel's point on the hull (its ray's
// distance + 1 in uViewHull, 0: the ray misses the hull, lit), moved uSunOffset toward the
// sun, is shaded where the hull reaches farther toward the sun along its line (layer s
// of uSunMaps: the largest l . p of the hull + 100 per texel across sun s, 0 where none).
uniform sampler2DArray uViewHull;
uniform vec3 uViewCentre;
uniform mat3 uViewAxes;
uniform vec4 uViewK;
uniform sampler2DArray uSunMaps;
uniform vec3 uSunAxesX[MAX_SUNS];
uniform vec3 uSunAxesY[MAX_SUNS];
uniform vec4 uSunBoxes[MAX_SUNS]; // lo x, lo y, hi x, hi y along the axes
uniform float uSunOffset;         // metres; < 0: no shadows
// The suns relit as frf relights them (uBasisSun 1: the export holds the basis images;
// player/src/sun.js makes these, sun_light.rs derives them): the basis' tiles (R8, layer
// 3 * view + channel, uBasisColumns tiles a row, value offset + scale * code), the
// conditions' table (column k: row 0 its cone, row 1 + s sun s's light per unit of its,
// rows 1 + MAX_SUNS.. its lights), and per sun at the view: its direction in the view's
// dome, the conditions the trust reads (the nearest first, 6 a sun), each nearest's
// held-out predictors (places among them), how compact it is, the condition whose region
// holds it, and its luminance (its weight among the suns' trusts).
uniform int uBasisSun;
uniform sampler2DArray uBasis;
uniform highp sampler2D uConditions;
uniform int uBasisColumns;
uniform int uConditionCount;
uniform int uLightsPer;
uniform vec3 uBasisScale[32];
uniform vec3 uBasisOffset[32];
uniform mat3 uDomeFromSubject;
uniform vec3 uSunDomes[MAX_SUNS];
uniform int uInvolved[6 * MAX_SUNS];
uniform int uInvolvedCount[MAX_SUNS];
uniform int uNearestCount[MAX_SUNS];
uniform float uNearestW[2 * MAX_SUNS];
uniform int uHeldPlace[4 * MAX_SUNS];
uniform float uHeldW[4 * MAX_SUNS];
uniform float uCompactness[MAX_SUNS];
uniform int uRegion[MAX_SUNS];
uniform float uSunLum[MAX_SUNS];
out vec4 outColor;

bool sunlit(ivec2 p, int s) {
  if (uSunOffset < 0.0) return true;
  float t = texelFetch(uViewHull, ivec3(p, uLayer), 0).r - 1.0;
  if (t < 0.0) return true;
  vec3 dc = vec3((float(p.x) - uViewK.z) / uViewK.x, (float(p.y) - uViewK.w) / uViewK.y, 1.0);
  vec3 surface = uViewCentre + normalize(uViewAxes * dc) * t;
  vec3 q = surface + uSunDirs[s] * uSunOffset;
  vec2 size = vec2(textureSize(uSunMaps, 0).xy);
  vec4 box = uSunBoxes[s];
  vec2 m = (vec2(dot(uSunAxesX[s], q), dot(uSunAxesY[s], q)) - box.xy) / (box.zw - box.xy) * size;
  if (any(lessThan(m, vec2(0.0))) || any(greaterThanEqual(m, size))) return true;
  float reach = texelFetch(uSunMaps, ivec3(ivec2(m), s), 0).r;
  if (reach == 0.0) return true;
  return !(reach - 100.0 > dot(uSunDirs[s], q));
}

// Condition k's image at texel p, per unit of its light, times sun s's light
// (SunLight::sunned).
vec3 sunned(ivec2 p, ivec2 size, int k, int s) {
  ivec2 a = p + ivec2((k % uBasisColumns) * size.x, (k / uBasisColumns) * size.y);
  vec3 code = uBasisPacked == 1 ? texelFetch(uBasis, ivec3(a, uLayer), 0).rgb * 255.0
    : vec3(texelFetch(uBasis, ivec3(a, 3 * uLayer), 0).r,
           texelFetch(uBasis, ivec3(a, 3 * uLayer + 1), 0).r,
           texelFetch(uBasis, ivec3(a, 3 * uLayer + 2), 0).r) * 255.0;
  return (uBasisOffset[k] + uBasisScale[k] * code) * texelFetch(uConditions, ivec2(k, 1 + s), 0).rgb;
}

// Condition k's shading of a unit normal n (dome frame), per unit of its light: n . m
// where n sees all its lights, 0 where none, its lights one by one between (cone_shading).
float shading(int k, vec3 n) {
  vec4 cone = texelFetch(uConditions, ivec2(k, 0), 0);
  float d = dot(n, cone.xyz);
  if (d >= cone.w) return d;
  if (d <= -cone.w) return 0.0;
  float s = 0.0;
  for (int j = 0; j < uLightsPer; j++) {
    vec4 l = texelFetch(uConditions, ivec2(k, 1 + MAX_SUNS + j), 0);
    s += l.w * max(dot(n, l.xyz), 0.0);
  }
  return s;
}

float lum(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// How far sun s's normals' relighting is trusted at texel p (SunLight::trust): its
// compactness times a smooth step down as the texel's leave-one-out error goes from 2 to
// 5 (TRUST_ERROR); and in lit, what the normals relight it to (relight_texel: the nearest
// conditions' images by the ratio of the normal's shading under the sun to theirs, or,
// where they barely reach the normal, the fit's shading scaled by every image's ratio).
float sunTrust(ivec2 p, ivec2 size, vec3 n, int s, out vec3 lit) {
  lit = vec3(0.0);
  float lums[6];
  float shades[6];
  vec3 photos[6];
  for (int j = 0; j < 6; j++) {
    if (j >= uInvolvedCount[s]) break;
    int k = uInvolved[6 * s + j];
    photos[j] = sunned(p, size, k, s);
    lums[j] = lum(photos[j]);
    shades[j] = shading(k, n);
  }
  float error = 0.0;
  float plain = 0.0;
  vec3 interpolatedRgb = vec3(0.0);
  float shadedRgb = 0.0;
  for (int j = 0; j < 2; j++) {
    if (j >= uNearestCount[s]) break;
    float w = uNearestW[2 * s + j];
    interpolatedRgb += w * photos[j];
    shadedRgb += w * shades[j];
    float shaded = 0.0;
    float interpolated = 0.0;
    for (int m = 0; m < 2; m++) {
      float wm = uHeldW[4 * s + 2 * j + m];
      if (wm == 0.0) continue;
      int place = uHeldPlace[4 * s + 2 * j + m];
      shaded += wm * shades[place];
      interpolated += wm * lums[place];
    }
    float wanted = shades[j];
    float predicted = wanted <= 0.0 ? 0.0
      : (shaded >= 0.3 * wanted ? interpolated * wanted / shaded : interpolated);
    error += w * abs(predicted - lums[j]);
    plain += w * abs(interpolated - lums[j]);
  }
  float e = plain > 0.0 ? error / plain : (error > 0.0 ? 1e30 : 0.0);
  float wanted = max(dot(n, uSunDomes[s]), 0.0);
  if (wanted > 0.0) {
    if (shadedRgb >= 0.3 * wanted) {
      lit = interpolatedRgb * wanted / shadedRgb;
    } else {
      vec3 num = vec3(0.0);
      float den = 0.0;
      for (int k = 0; k < 32; k++) {
        if (k >= uConditionCount) break;
        float m = shading(k, n);
        if (m > 0.0) {
          num += sunned(p, size, k, s) * m;
          den += m * m;
        }
      }
      if (den > 0.0) lit = wanted * num / den;
    }
  }
  return uCompactness[s] <= 0.0 ? 0.0 : uCompactness[s] * (1.0 - smoothstep(2.0, 5.0, e));
}

// The suns at texel p as frf relights them (suns_texel): their basis' light (each sun's
// condition image), moved toward the normals' by the suns' trust weighted by their
// luminance; a sun counts where the hull does not hide it.
vec3 basisSuns(ivec2 p, ivec2 size, bool hasNormal, vec3 n) {
  vec3 basis = vec3(0.0);
  for (int s = 0; s < MAX_SUNS; s++) {
    if (s >= uSunCount) break;
    basis += sunned(p, size, uRegion[s], s);
  }
  if (!hasNormal) return basis;
  float trusted = 0.0;
  float total = 0.0;
  vec3 lit = vec3(0.0);
  for (int s = 0; s < MAX_SUNS; s++) {
    if (s >= uSunCount) break;
    vec3 sunLit;
    trusted += uSunLum[s] * sunTrust(p, size, n, s, sunLit);
    total += uSunLum[s];
    if (any(notEqual(sunLit, vec3(0.0))) && sunlit(p, s)) lit += sunLit;
  }
  float t = total > 0.0 ? trusted / total : 0.0;
  return t <= 0.0 ? basis : basis + t * (lit - basis);
}

void main() {
  // Texel (x, y) of the view, y down: row y of the layer, as the views' data textures
  // (uploaded top row first) are read by texelFetch.
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 size = ivec2(textureSize(uAlpha, 0).xy);
  float alpha = texelFetch(uAlpha, ivec3(p, uLayer), 0).r;
  vec3 rgb = vec3(0.0);
  if (alpha > 0.0) {
    for (int i = 0; i < 9; i++) {
      ivec2 a = p + ivec2((i % 3) * size.x, (i / 3) * size.y);
      vec3 t;
      if (uCompact == 1) {
        float code = texelFetch(uAtlas, ivec3(a, uLayer), 0).r * 255.0;
        vec3 colour = texelFetch(uAlbedo, ivec3(p, 2 * uLayer + 1), 0).rgb * 255.0 * uColourScale;
        t = (uOffset[i].x + uScale[i].x * code) * colour;
      } else {
        vec3 code = uAtlasPacked == 1 ? texelFetch(uAtlas, ivec3(a, uLayer), 0).rgb * 255.0
          : vec3(texelFetch(uAtlas, ivec3(a, 3 * uLayer), 0).r,
                 texelFetch(uAtlas, ivec3(a, 3 * uLayer + 1), 0).r,
                 texelFetch(uAtlas, ivec3(a, 3 * uLayer + 2), 0).r) * 255.0;
        t = uOffset[i] + uScale[i] * code;
      }
      rgb += uSh[i] * t;
    }
    if (uSunCount > 0) {
      vec4 n = uHasNormals == 1 ? texelFetch(uNormals, ivec3(p, uLayer), 0) : vec4(0.0);
      if (uBasisSun == 1) {
        rgb += basisSuns(p, size, n.a > 0.0, normalize(uDomeFromSubject * (n.rgb * 2.0 - 1.0)));
      } else if (n.a > 0.0) {
        vec3 albedo = texelFetch(uAlbedo, ivec3(p, 2 * uLayer), 0).rgb * 255.0 * uAlbedoScale;
        vec3 normal = normalize(n.rgb * 2.0 - 1.0);
        for (int s = 0; s < MAX_SUNS; s++) {
          if (s >= uSunCount) break;
          float facing = max(dot(normal, uSunDirs[s]), 0.0);
          if (facing > 0.0 && sunlit(p, s)) rgb += albedo * facing * uSunEs[s];
        }
      }
    }
  }
  // Texels that relight negative (an L2 light rings below zero) are black, as in frf; a
  // light too bright for half floats saturates (an overflow to infinity drew it dark).
  outColor = vec4(clamp(rgb, vec3(0.0), vec3(65504.0)), alpha);
}
`;

/**
 * The hull passes: each pixel's distance along its unit ray to the hull mesh, plus 1 (0:
 * none); and the sun's map of the hull: l . p + 100 of the surface nearest the sun.
 */
export const HULL_VERTEX = /* glsl */ `
precision highp float;
in vec3 position;
uniform mat4 uViewProjection;
out vec3 vWorld;
void main() {
  vWorld = position;
  gl_Position = uViewProjection * vec4(position, 1.0);
}
`;
export const HULL_FRAGMENT = /* glsl */ `
precision highp float;
in vec3 vWorld;
uniform vec3 uEye;
out vec4 outColor;
void main() { outColor = vec4(length(vWorld - uEye) + 1.0, 0.0, 0.0, 1.0); }
`;
/**
 * A pass drawn as tiles of the frame (player.js `#tile`): point sprites uPointSize
 * across at their centres, or triangles' corners, in clip space.
 */
export const TILE_VERTEX = /* glsl */ `
precision highp float;
in vec2 position;
uniform float uPointSize;
void main() {
  gl_Position = vec4(position, 0.0, 1.0);
  gl_PointSize = uPointSize;
}
`;
export const SUN_MAP_VERTEX = /* glsl */ `
precision highp float;
in vec3 position;
uniform vec3 uSunDir;
uniform vec3 uSunAxisX;
uniform vec3 uSunAxisY;
uniform vec4 uSunBox;
uniform vec2 uReach;              // the range of l . p over the hull: nearest the sun in front
out float vReach;
void main() {
  vReach = dot(uSunDir, position);
  vec2 m = (vec2(dot(uSunAxisX, position), dot(uSunAxisY, position)) - uSunBox.xy) / (uSunBox.zw - uSunBox.xy);
  gl_Position = vec4(m * 2.0 - 1.0, 1.0 - 2.0 * (vReach - uReach.x) / (uReach.y - uReach.x), 1.0);
}
`;
export const SUN_MAP_FRAGMENT = /* glsl */ `
precision highp float;
in float vReach;
out vec4 outColor;
void main() { outColor = vec4(vReach + 100.0, 0.0, 0.0, 1.0); }
`;

/** The frame pass. */
export const FRAME_FRAGMENT = /* glsl */ `
precision highp float;
precision highp int;
precision highp sampler2DArray;
uniform vec3 uEye;
uniform mat3 uAxes;      // columns: right, down, forward (subject frame)
uniform vec4 uK;         // fx, fy, cx, cy
uniform int uHeight;     // the frame's rows
uniform sampler2D uQuads;
uniform int uQuadCount;
uniform sampler2D uFrames;
uniform sampler2D uViews;       // per grid view: centre + pre-lit layer, flow layers
uniform int uColumns;
uniform int uRows;
uniform int uFrameRows;
uniform sampler2DArray uPrelit; // RGBA16F, premultiplied linear
uniform sampler2DArray uMotion; // RG32F, metres across the axis and up it (alpha 1)
uniform int uWithMotion;        // 1: the views' motion morphed too, into outMotion
uniform int uQuadIds;           // 1: each pixel's quad instead of its colour
uniform sampler2DArray uFlows;  // RG32F, pixels
uniform sampler2D uHullT;       // R32F: distance to the hull along the ray + 1, 0 none
uniform int uHasHull;
uniform vec2 uAxis;
layout(location = 0) out vec4 outColor;
layout(location = 1) out vec4 outMotion;

// Fixed-point steps per source at most, and from the proxy's depth (frf's
// solved::ITERATIONS and solved::PROXY_ITERATIONS).
const int SOLVE_ITERATIONS = 2;
const int PROXY_ITERATIONS = 1;
const float SETTLED_PX = 0.01;
const float SETTLE_PX = 2.0;
const float SETTLE_FLOOR = 1e-3;
const float BIG = 3.4e38;
const int NONE = 1 << 30;

float cross2(vec2 m, vec2 n) { return m.x * n.y - m.y * n.x; }
bool finite(float x) { return abs(x) <= BIG; }
vec3 normalizeOrZero(vec3 v) { float l = length(v); return l > 0.0 ? v / l : vec3(0.0); }
float outside(vec2 bg) {
  return max(max(-bg.x, bg.x - 1.0), 0.0) + max(max(-bg.y, bg.y - 1.0), 0.0);
}
float betaFor(float g, vec2 q, vec2 a, vec2 b, vec2 c) {
  vec2 d = a + c * g;
  if (abs(d.x) >= abs(d.y)) return (q.x - g * b.x) / d.x;
  return (q.y - g * b.y) / d.y;
}

// The inverse bilinear map on a quad, in its plane; .z = 1 when solved.
vec3 inverseBilinear(vec3 p, vec3 p00, vec3 e1, vec3 e2, vec3 e3, vec3 normal) {
  vec3 xAxis = normalizeOrZero(e1);
  vec3 yAxis = cross(normal, xAxis);
  vec2 q = vec2(dot(p - p00, xAxis), dot(p - p00, yAxis));
  vec2 a = vec2(dot(e1, xAxis), dot(e1, yAxis));
  vec2 b = vec2(dot(e2, xAxis), dot(e2, yAxis));
  vec2 c = vec2(dot(e3, xAxis), dot(e3, yAxis));
  float k2 = cross2(c, b);
  float k1 = cross2(a, b) - cross2(c, q);
  float k0 = -cross2(a, q);
  float scale = max(max(abs(k1), abs(k0)), 1e-30);
  vec3 best = vec3(0.0);
  float bestOut = BIG;
  float roots[2];
  int count = 0;
  if (abs(k2) <= 1e-6 * scale) {
    if (abs(k1) < 1e-30) return best;
    roots[0] = -k0 / k1;
    count = 1;
  } else {
    float disc = k1 * k1 - 4.0 * k2 * k0;
    if (disc < 0.0) return best;
    float s = sqrt(disc);
    float qq = -0.5 * (k1 + (k1 >= 0.0 ? 1.0 : -1.0) * s);
    roots[0] = qq / k2;
    count = 1;
    if (abs(qq) > 1e-30) { roots[1] = k0 / qq; count = 2; }
  }
  for (int i = 0; i < count; i++) {
    float g = roots[i];
    float beta = betaFor(g, q, a, b, c);
    if (!finite(beta)) continue;
    float o = outside(vec2(beta, g));
    if (o < bestOut) { bestOut = o; best = vec3(beta, g, 1.0); }
  }
  return best;
}

struct Hit { int u; int v; float beta; float gamma; vec3 point; float t; int clamped; };

vec4 quadTexel(int i, int k) { return texelFetch(uQuads, ivec2(k, i), 0); }

// The column index (geometry.js columnIndex): spans' azimuth ranges (uRanges, .xy per
// texel), the annulus about the axis point, and whether it is used.
uniform sampler2D uRanges;
uniform int uIndexed;
uniform vec2 uColAxis;
uniform vec2 uColReference;
uniform float uColOrientation;
uniform float uRMin;
uniform float uRMax;
uniform int uSpans;
uniform int uQuadsPerSpan;
const float TAU = 6.2831855;

// Offers quad i: where the ray meets its plane, kept when inside the quad (its four
// edges' tests, geometry.js quadTexels: frf's EDGE_SLACK as a band along the edges)
// and nearer than the best so far (of equal ones the first quad's); and whether any
// lies ahead. Its bilinear coordinates are solved once, for the quad kept (hitOn).
void offer(int i, vec3 origin, vec3 dir, inout float bestT, inout int bestIndex, inout bool anyAhead) {
  vec4 plane = quadTexel(i, 5);
  float denom = dot(plane.xyz, dir);
  float t = (plane.w - dot(plane.xyz, origin)) / denom;
  vec4 p = vec4(origin + dir * t, -1.0);
  vec4 s = vec4(dot(quadTexel(i, 6), p), dot(quadTexel(i, 7), p), dot(quadTexel(i, 8), p), dot(quadTexel(i, 9), p));
  bool inside = abs(denom) >= 1e-9 && min(min(s.x, s.y), min(s.z, s.w)) >= 0.0;
  if (inside && t >= 0.0) anyAhead = true;
  if (inside && (t < bestT || (t == bestT && i < bestIndex))) {
    bestT = t;
    bestIndex = i;
  }
}

// The ray's hit on quad i (frf's): its column and row, its bilinear coordinates (the
// wall's gamma above and below the grid) and point.
Hit hitOn(int i, vec3 origin, vec3 dir) {
  vec4 t0 = quadTexel(i, 0), t1 = quadTexel(i, 1), t2 = quadTexel(i, 2), t3 = quadTexel(i, 3), t4 = quadTexel(i, 4);
  float t = dot(t4.xyz, t0.xyz - origin) / dot(t4.xyz, dir);
  vec3 p = origin + dir * t;
  vec3 r = inverseBilinear(p, t0.xyz, t1.xyz, t2.xyz, t3.xyz, t4.xyz);
  int wall = int(t2.w);
  float gamma = wall != 0 ? t3.w : clamp(r.y, 0.0, 1.0);
  return Hit(int(t0.w), int(t1.w), clamp(r.x, 0.0, 1.0), gamma, p, t, wall);
}

float turn(vec2 s, vec2 e) { return atan(cross2(s, e), dot(s, e)); }
float columnAzimuth(vec2 v) {
  float s = uColOrientation * turn(uColReference, v);
  return s < 0.0 ? s + TAU : s;
}
vec2 spanRange(int u) { return texelFetch(uRanges, ivec2(u, 0), 0).xy; }

// Offers the quads of every span whose range meets the azimuths swept from start to end.
void walkSpans(vec2 start, vec2 end, vec3 origin, vec3 dir, inout float bestT, inout int bestIndex, inout bool anyAhead) {
  float sweep = uColOrientation * turn(start, end);
  float a = columnAzimuth(start);
  float len = sweep;
  if (sweep < 0.0) { a = columnAzimuth(end); len = -sweep; }
  float last = spanRange(uSpans - 1).y;
  a -= TAU * ceil((a - last) / TAU);
  if (a > last) a -= TAU;
  if (a <= last - TAU) a += TAU;
  float b = a + len;
  int lo = 0, hi = uSpans;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (spanRange(mid).y < a) lo = mid + 1; else hi = mid;
  }
  for (int u = lo; u < uSpans && spanRange(u).x <= b; u++) {
    for (int k = 0; k < uQuadsPerSpan; k++) offer(u * uQuadsPerSpan + k, origin, dir, bestT, bestIndex, anyAhead);
  }
  for (int u = 0; u < uSpans && spanRange(u).x + TAU <= b; u++) {
    for (int k = 0; k < uQuadsPerSpan; k++) offer(u * uQuadsPerSpan + k, origin, dir, bestT, bestIndex, anyAhead);
  }
}

// Where the ray enters the cylinder: the smallest t of all hits, unless none lies ahead
// (clamped = 3). Only the spans the ray's line can reach are tested (every quad without
// the index), as frf does.
Hit intersect(vec3 origin, vec3 dir) {
  float bestT = BIG;
  int bestIndex = NONE;
  bool anyAhead = false;
  if (uIndexed == 0) {
    for (int i = 0; i < uQuadCount; i++) offer(i, origin, dir, bestT, bestIndex, anyAhead);
  } else {
    vec2 o = origin.xz - uColAxis;
    float m = max(abs(dir.x), abs(dir.z));
    if (m == 0.0) {
      float r = length(o);
      if (r >= uRMin && r <= uRMax) walkSpans(o, o, origin, dir, bestT, bestIndex, anyAhead);
    } else {
      vec2 d = normalize(dir.xz / m);
      vec2 across = vec2(-d.y, d.x);
      float h = dot(o, across);
      if (abs(h) <= uRMax) {
        vec2 foot = across * h;
        float outer = sqrt(uRMax * uRMax - h * h);
        if (abs(h) >= uRMin) {
          walkSpans(foot - d * outer, foot + d * outer, origin, dir, bestT, bestIndex, anyAhead);
        } else {
          float inner = sqrt(uRMin * uRMin - h * h);
          walkSpans(foot - d * outer, foot - d * inner, origin, dir, bestT, bestIndex, anyAhead);
          walkSpans(foot + d * inner, foot + d * outer, origin, dir, bestT, bestIndex, anyAhead);
        }
      }
    }
  }
  if (bestIndex == NONE || !anyAhead) return Hit(0, 0, 0.0, 0.0, vec3(0.0), BIG, 3);
  return hitOn(bestIndex, origin, dir);
}

vec4 bilinearWeights(float beta, float gamma) {
  float b = 1.0 - beta, g = 1.0 - gamma;
  return vec4(b * g, beta * g, b * gamma, beta * gamma);
}

ivec4 quadViews(Hit hit) {
  int top = uRows > 1 ? hit.v + 1 : hit.v;
  int bottom = min(hit.v, uRows - 1);
  int upper = min(top, uRows - 1);
  int u0 = hit.u % uColumns, u1 = (hit.u + 1) % uColumns;
  return ivec4(u0 * uRows + bottom, u1 * uRows + bottom, u0 * uRows + upper, u1 * uRows + upper);
}

vec4 viewTexel(int view, int k) { return texelFetch(uViews, ivec2(k, view), 0); }

// The rectified frame of a quad: 32 texels (geometry.js frameTexels).
vec4 frameTexel(int f, int k) { return texelFetch(uFrames, ivec2(k, f), 0); }
int frameIndex(Hit hit) { return (hit.u % uColumns) * uFrameRows + min(hit.v, uFrameRows - 1); }
mat3 frameMatrix(int f, int first) {
  return mat3(frameTexel(f, first).xyz, frameTexel(f, first + 1).xyz, frameTexel(f, first + 2).xyz);
}
mat3 toRectified(int f, int k) { return frameMatrix(f, 4 + 3 * k); }
mat3 fromRectified(int f, int k) { return frameMatrix(f, 16 + 3 * k); }
vec2 frameCentre(int f, int k) {
  vec4 pair = frameTexel(f, 28 + k / 2);
  return (k % 2 == 0) ? pair.xy : pair.zw;
}
vec3 toPlane(int f, vec3 p) {
  return vec3(dot(frameTexel(f, 0).xyz, p), dot(frameTexel(f, 1).xyz, p), dot(frameTexel(f, 2).xyz, p));
}
vec3 projectRectified(int f, vec3 dir) {
  vec3 d = toPlane(f, dir);
  if (d.z <= 1e-6 * length(dir)) return vec3(0.0);
  vec4 k = frameTexel(f, 3);
  return vec3(k.x * d.x / d.z + k.z, k.y * d.y / d.z + k.w, 1.0);
}
vec2 homography(mat3 h, vec2 p) {
  vec3 q = h * vec3(p, 1.0);
  float z = abs(q.z) < 1e-6 ? 1e-6 : q.z;
  return q.xy / z;
}

// The ray's point on the proxy (w = 1), or w = 0: its hit on the hull mesh, else its
// point nearest the hull's vertical axis.
vec4 proxyPoint(vec3 origin, vec3 dir) {
  if (uHasHull == 0) return vec4(0.0);
  float t = texelFetch(uHullT, ivec2(gl_FragCoord.xy), 0).r - 1.0;
  if (t >= 0.0) return vec4(origin + dir * t, 1.0);
  vec2 o = origin.xz - uAxis;
  vec2 d = dir.xz;
  float dd = dot(d, d);
  if (dd < 1e-8) return vec4(0.0);
  return vec4(origin + dir * max(-dot(o, d) / dd, 0.0), 1.0);
}

struct Output { vec2 centre; vec2 s; float inverseDepth; bool ok; int steps; };

Output solvedOutput(Hit hit, vec3 origin, vec3 dir) {
  Output out_ = Output(vec2(0.0), vec2(0.0), 0.0, false, SOLVE_ITERATIONS);
  int f = frameIndex(hit);
  if (frameTexel(f, 0).w == 0.0) return out_;
  vec4 point = proxyPoint(origin, dir);
  vec3 centre = hit.point;
  vec3 r;
  if (hit.clamped == 0 || uRows == 1) {
    r = projectRectified(f, dir);
  } else {
    ivec4 q = quadViews(hit);
    vec4 w = bilinearWeights(hit.beta, hit.gamma);
    centre = vec3(0.0);
    for (int i = 0; i < 4; i++) centre += viewTexel(q[i], 0).xyz * w[i];
    r = point.w > 0.0 ? projectRectified(f, point.xyz - centre) : projectRectified(f, dir);
  }
  if (r.z == 0.0) return out_;
  vec3 plane = toPlane(f, centre);
  float inverseDepth = 1.0 / frameTexel(f, 30).x;
  int steps = SOLVE_ITERATIONS;
  if (point.w > 0.0) {
    float v = 1.0 / (toPlane(f, point.xyz).z - plane.z);
    if (finite(v) && v > 0.0) {
      inverseDepth = v;
      steps = PROXY_ITERATIONS;
    }
  }
  return Output(plane.xy, r.xy, inverseDepth, true, steps);
}

// A bilinear sample of a layer at pixel s (centres at integers, the edge
// repeated): frf's crop_position and its four texels.
vec4 bilinearLayer(sampler2DArray tex, int layer, vec2 s) {
  ivec2 size = textureSize(tex, 0).xy;
  vec2 p = clamp(s, vec2(-1.0), vec2(size));
  vec2 p0 = floor(p);
  vec2 fr = p - p0;
  ivec2 a = clamp(ivec2(p0), ivec2(0), size - 1);
  ivec2 b = clamp(ivec2(p0) + 1, ivec2(0), size - 1);
  vec4 c00 = texelFetch(tex, ivec3(a, layer), 0);
  vec4 c10 = texelFetch(tex, ivec3(b.x, a.y, layer), 0);
  vec4 c01 = texelFetch(tex, ivec3(a.x, b.y, layer), 0);
  vec4 c11 = texelFetch(tex, ivec3(b, layer), 0);
  return mix(mix(c00, c10, fr.x), mix(c01, c11, fr.x), fr.y);
}

// A view's flow toward neighbour dir (0 right, 1 left, 2 up, 3 down) at pixel s, in
// pixels; absent flows are zero.
vec2 sampleFlow(int view, int dir, vec2 s) {
  int layer = int(viewTexel(view, 1)[dir]);
  return layer < 0 ? vec2(0.0) : bilinearLayer(uFlows, layer, s).rg;
}

// A view's pre-lit premultiplied colour at pixel s; views not held are transparent.
vec4 samplePrelit(int view, vec2 s) {
  int layer = int(viewTexel(view, 0).w);
  return layer < 0 ? vec4(0.0) : bilinearLayer(uPrelit, layer, s);
}

vec2 solveFractions(int f, int k, bool vertical, vec2 to) {
  vec2 c = frameCentre(f, k);
  vec2 o = to - c;
  vec2 b1 = frameCentre(f, k ^ 1) - c;
  vec2 b2 = frameCentre(f, k ^ 2) - c;
  float det = cross2(b1, b2);
  if (vertical && abs(det) > 1e-9) return vec2(cross2(o, b2) / det, cross2(b1, o) / det);
  return vec2(dot(o, b1) / max(dot(b1, b1), 1e-12), 0.0);
}

// The pixel of vertex k that shows the output's point (.xy), and the last step (.z).
vec3 solveSource(int f, ivec4 q, int k, Output o) {
  int h = k ^ 1;
  int v = k ^ 2;
  bool vertical = q[v] != q[k];
  vec2 ac = solveFractions(f, k, vertical, o.centre);
  int towardH = (k % 2 == 0) ? 0 : 1;
  int towardV = (k < 2) ? 2 : 3;
  int view = q[k];
  vec4 kf = frameTexel(f, 3);
  vec2 focal = kf.xy;
  vec2 across = vec2(0.0);
  vec2 along = vec2(0.0);
  if (!vertical) {
    vec2 c = frameCentre(f, k);
    vec2 b = frameCentre(f, h) - c;
    across = (o.centre - c - b * ac.x) * focal;
    vec2 p = b * focal;
    along = p / max(dot(p, p), 1e-12);
  }
  mat3 fromK = fromRectified(f, k);
  mat3 toH = toRectified(f, h);
  mat3 toV = toRectified(f, v);
  vec2 here = o.s + (o.centre - frameCentre(f, k)) * focal * o.inverseDepth;
  vec2 x = homography(fromK, here);
  float step_ = 0.0;
  for (int i = 0; i < o.steps; i++) {
    vec2 d = vec2(0.0);
    if (ac.x != 0.0 || any(notEqual(across, vec2(0.0)))) {
      vec2 fh = sampleFlow(view, towardH, x);
      vec2 dh = homography(toH, x + fh) - here;
      d += ac.x * dh + across * dot(dh, along);
    }
    if (ac.y != 0.0) {
      vec2 fv = sampleFlow(view, towardV, x);
      d += ac.y * (homography(toV, x + fv) - here);
    }
    here = o.s - d;
    vec2 next = homography(fromK, here);
    step_ = length(next - x);
    x = next;
    if (step_ < SETTLED_PX) break;
  }
  return vec3(x, step_);
}

// A view's motion at pixel s (alpha 1 where the view is held, as its pre-lit colour).
vec4 sampleMotion(int view, vec2 s) {
  int layer = int(viewTexel(view, 0).w);
  return layer < 0 ? vec4(0.0) : bilinearLayer(uMotion, layer, s);
}

// The four sources solved and mixed: the pre-lit colour into outColor, and with
// uWithMotion the views' motion, by the same samples' weights, into outMotion.
void solvedMorph(Hit hit, Output o) {
  int f = frameIndex(hit);
  ivec4 q = quadViews(hit);
  vec4 w = bilinearWeights(hit.beta, hit.gamma);
  vec4 acc = vec4(0.0);
  vec4 motion = vec4(0.0);
  float total = 0.0;
  for (int k = 0; k < 4; k++) {
    if (w[k] <= 0.0) continue;
    vec3 r = solveSource(f, q, k, o);
    float settle = r.z / SETTLE_PX;
    float wk = w[k] * max(exp(-(settle * settle)), SETTLE_FLOOR);
    acc += samplePrelit(q[k], r.xy) * wk;
    if (uWithMotion == 1) motion += sampleMotion(q[k], r.xy) * wk;
    total += wk;
  }
  outColor = total > 0.0 ? acc / total : acc;
  outMotion = total > 0.0 ? motion / total : motion;
}

void main() {
  // Pixel (x, y), y down, centres at integers (the target's rows run bottom up).
  vec2 pixel = vec2(floor(gl_FragCoord.x), float(uHeight - 1) - floor(gl_FragCoord.y));
  vec3 dc = vec3((pixel.x - uK.z) / uK.x, (pixel.y - uK.w) / uK.y, 1.0);
  vec3 dir = normalize(uAxes * dc);
  Hit hit = intersect(uEye, dir);
  outColor = vec4(0.0);
  outMotion = vec4(0.0);
  if (hit.clamped == 3) return;
  // The quad mode: which quad the pixel's ray reads (its column, row, and 1), not its
  // colour (the views a camera needs decoded, FrfPlayer's #viewsReached).
  if (uQuadIds == 1) {
    outColor = vec4(float(hit.u % uColumns), float(hit.v), 1.0, 0.0);
    return;
  }
  Output o = solvedOutput(hit, uEye, dir);
  if (!o.ok) return;
  solvedMorph(hit, o);
}
`;

/** The page's present pass: a frame (premultiplied linear) over a backdrop, exposed, sRGB. */
export const PRESENT_FRAGMENT = /* glsl */ `
precision highp float;
uniform sampler2D uFrame;
uniform float uExposure;          // a factor
uniform vec3 uTop;
uniform vec3 uBottom;
uniform vec2 uSize;
out vec4 outColor;
vec3 srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
void main() {
  vec4 f = texelFetch(uFrame, ivec2(gl_FragCoord.xy), 0);
  vec3 backdrop = mix(uBottom, uTop, gl_FragCoord.y / uSize.y);
  outColor = vec4(srgb(f.rgb * uExposure + backdrop * (1.0 - f.a)), 1.0);
}
`;

/**
 * The morph in time (frf's `shaders/time_morph.wgsl`): the frame a fraction uS of the way
 * from pose k to k' samples k's render where the point was (back along k''s motion toward
 * k, a fraction uS of it) and k''s where it will be (along k's motion, 1 − uS of it) and
 * mixes them (1 − uS, uS). Motion renders hold metres across the axis and up it (.rg
 * over .a; none where .a is 0), uToImage turns them into the frame's pixels.
 */
export const TIME_MORPH_FRAGMENT = /* glsl */ `
precision highp float;
precision highp int;
uniform sampler2D uBefore;        // pose k, premultiplied linear
uniform sampler2D uAfter;         // pose k'
uniform sampler2D uBeforeMotion;  // k's motion toward k'
uniform sampler2D uAfterMotion;   // k''s motion toward k
uniform mat2 uToImage;
uniform float uS;
uniform int uHeight;
out vec4 outColor;

// Pixel p (y down) of a target whose rows run bottom up.
vec4 at(sampler2D t, ivec2 p) { return texelFetch(t, ivec2(p.x, uHeight - 1 - p.y), 0); }

vec2 motionAt(sampler2D t, ivec2 p) {
  vec4 m = at(t, p);
  return m.a < 1e-3 ? vec2(0.0) : uToImage * (m.rg / m.a);
}

// Bilinear at pixel q (centres at integers), zero beyond the frame (frf's Border::Zero).
vec4 bilinearZero(sampler2D t, vec2 q) {
  ivec2 size = textureSize(t, 0);
  float limit = float(max(size.x, size.y) + 2);
  vec2 c = clamp(q, vec2(-limit), vec2(size) + limit);
  vec2 f0 = floor(c);
  vec2 fr = c - f0;
  ivec2 i0 = ivec2(f0);
  vec4 acc = vec4(0.0);
  for (int dy = 0; dy < 2; dy++) {
    for (int dx = 0; dx < 2; dx++) {
      float w = (dx == 1 ? fr.x : 1.0 - fr.x) * (dy == 1 ? fr.y : 1.0 - fr.y);
      ivec2 p = i0 + ivec2(dx, dy);
      if (w != 0.0 && all(greaterThanEqual(p, ivec2(0))) && all(lessThan(p, size))) acc += w * at(t, p);
    }
  }
  return acc;
}

void main() {
  ivec2 p = ivec2(int(gl_FragCoord.x), uHeight - 1 - int(gl_FragCoord.y));
  vec2 here = vec2(p);
  vec4 a = bilinearZero(uBefore, here + uS * motionAt(uAfterMotion, p));
  vec4 b = bilinearZero(uAfter, here + (1.0 - uS) * motionAt(uBeforeMotion, p));
  outColor = (1.0 - uS) * a + uS * b;
}
`;

/**
 * The walker over a three.js scene: its frame (premultiplied) with the depth of its
 * hull (the nearer of the two poses' between poses; where a pixel's ray misses the hull,
 * its point nearest the hull's axis), so the scene's depth test hides what is behind.
 */
export const DEPTH_COMPOSITE_FRAGMENT = /* glsl */ `
precision highp float;
precision highp int;
uniform sampler2D uFrame;
uniform sampler2D uHullA;        // distance to the hull along the ray + 1, 0 none
uniform sampler2D uHullB;
uniform int uTwo;
uniform vec3 uEye;               // the subject-frame camera
uniform mat3 uAxes;
uniform vec4 uK;
uniform int uHeight;
uniform vec2 uAxis;
uniform mat4 uSubjectToClip;     // the scene camera's projection, view, and the walker's world
uniform int uDepth;
out vec4 outColor;

void main() {
  ivec2 q = ivec2(gl_FragCoord.xy);
  vec4 c = texelFetch(uFrame, q, 0);
  if (c.a <= 0.0) discard;
  vec2 pixel = vec2(float(q.x), float(uHeight - 1 - q.y));
  vec3 dir = normalize(uAxes * vec3((pixel.x - uK.z) / uK.x, (pixel.y - uK.w) / uK.y, 1.0));
  float a = texelFetch(uHullA, q, 0).r - 1.0;
  float b = uTwo == 1 ? texelFetch(uHullB, q, 0).r - 1.0 : -1.0;
  float t = a >= 0.0 && b >= 0.0 ? min(a, b) : max(a, b);
  if (t < 0.0) {
    vec2 o = uEye.xz - uAxis;
    vec2 d = dir.xz;
    float dd = dot(d, d);
    t = dd < 1e-8 ? 0.0 : max(-dot(o, d) / dd, 0.0);
  }
  vec4 clip = uSubjectToClip * vec4(uEye + dir * t, 1.0);
  gl_FragDepth = uDepth == 1 ? clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0) : 0.0;
  outColor = c;
}
`;

/**
 * The ground-shadow maps relit (frf's `ShadowMaps::relight`): per texel and channel
 * S = Σ_m w_m A_m / Σ_m w_m, within [0, 1], 1 where nothing lights the ground from above.
 */
export const GROUND_SHADOW_RELIGHT_FRAGMENT = /* glsl */ `
precision highp float;
precision highp int;
precision highp sampler2DArray;
uniform sampler2DArray uMaps;    // R8: a map a layer, rows along +z
uniform vec3 uWeights[64];
uniform int uCount;
out vec4 outColor;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 lit = vec3(0.0);
  vec3 total = vec3(0.0);
  for (int m = 0; m < uCount; m++) {
    lit += uWeights[m] * texelFetch(uMaps, ivec3(p, m), 0).r;
    total += uWeights[m];
  }
  vec3 s = vec3(1.0);
  for (int c = 0; c < 3; c++) if (total[c] > 0.0) s[c] = clamp(lit[c] / total[c], 0.0, 1.0);
  outColor = vec4(s, 1.0);
}
`;

/**
 * The ground's relative irradiance at ground point (x, z) of the subject frame (frf's
 * `RelitShadow::at`): bilinear between texel centres, the edge texels held out to the
 * border, faded to 1 toward the patch's edge, 1 off it. Needs uShadow (the relit maps,
 * rows along +z), uShadowExtent, uShadowFadeFrom.
 */
export const GROUND_SHADOW_AT = /* glsl */ `
vec3 groundShadowAt(vec2 xz) {
  float half_ = 0.5 * uShadowExtent;
  if (abs(xz.x) > half_ || abs(xz.y) > half_) return vec3(1.0);
  vec2 size = vec2(textureSize(uShadow, 0));
  vec2 t = (xz + half_) / (uShadowExtent / size) - 0.5;
  vec2 c = clamp(t, vec2(0.0), size - 1.0);
  vec2 f0 = floor(c);
  vec2 fr = c - f0;
  ivec2 a = ivec2(f0);
  ivec2 b = min(a + 1, ivec2(size) - 1);
  vec3 s = mix(mix(texelFetch(uShadow, a, 0).rgb, texelFetch(uShadow, ivec2(b.x, a.y), 0).rgb, fr.x),
               mix(texelFetch(uShadow, ivec2(a.x, b.y), 0).rgb, texelFetch(uShadow, b, 0).rgb, fr.x), fr.y);
  float e = clamp((max(abs(xz.x), abs(xz.y)) / half_ - uShadowFadeFrom) / (1.0 - uShadowFadeFrom), 0.0, 1.0);
  float w = e * e * (3.0 - 2.0 * e);
  return s + (1.0 - s) * w;
}
`;

/** The ground shadow as a frame layer: each pixel's ray met with the ground y = 0. */
export const GROUND_SHADOW_LAYER_FRAGMENT = /* glsl */ `
precision highp float;
uniform vec3 uEye;
uniform mat3 uAxes;
uniform vec4 uK;
uniform int uHeight;
uniform sampler2D uShadow;
uniform float uShadowExtent;
uniform float uShadowFadeFrom;
out vec4 outColor;
${GROUND_SHADOW_AT}
void main() {
  vec2 pixel = vec2(floor(gl_FragCoord.x), float(uHeight - 1) - floor(gl_FragCoord.y));
  vec3 dir = normalize(uAxes * vec3((pixel.x - uK.z) / uK.x, (pixel.y - uK.w) / uK.y, 1.0));
  vec3 s = vec3(1.0);
  if (dir.y < 0.0 && uEye.y > 0.0) {
    vec3 hit = uEye + dir * (-uEye.y / dir.y);
    s = groundShadowAt(hit.xz);
  }
  outColor = vec4(s, 1.0);
}
`;
