// Split-sum image-based lighting (Karis 2013, "Real Shading in Unreal Engine
// 4"): GGX importance sampling, the prefiltered radiance of one roughness,
// the cosine-filtered radiance, and the DFG table. GLSL only: it samples a
// cube map.
//
// Roughness is perceptual: alpha = roughness^2 (Karis 2013, after Burley
// 2012); the mip chain maps level l of L levels to roughness l / (L - 1).
// Samples are taken with "filtered importance sampling" (Colbert & Krivanek,
// GPU Gems 3 ch. 20): each sample reads the source cube at the mip whose
// texels cover the solid angle 1 / (n pdf) the sample stands for, so a few
// hundred samples give a smooth result and a bright texel (the Sun's
// neighbourhood) is spread over a sample's footprint instead of making
// fireflies.
#ifndef SKYBAKE_IBL_GLSL
#define SKYBAKE_IBL_GLSL

const float kIblPi = 3.14159265358979323846;

// Van der Corput radical inverse in base 2, and the Hammersley point i of n.
float RadicalInverseVdC(uint bits) {
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return float(bits) * 2.3283064365386963e-10;  // / 2^32
}
vec2 Hammersley(uint i, uint n) { return vec2((float(i) + 0.5) / float(n), RadicalInverseVdC(i)); }

// GGX (Trowbridge-Reitz) normal distribution, normalized so that the
// integral of D(h) (n.h) over the hemisphere is 1.
float DGgx(float n_dot_h, float alpha) {
  float a2 = alpha * alpha;
  float d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
  return a2 / (kIblPi * d * d);
}

// An orthonormal frame around unit n: columns tangent, bitangent, n.
mat3 FrameAround(vec3 n) {
  vec3 up = abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
  vec3 t = normalize(cross(up, n));
  return mat3(t, cross(n, t), n);
}

// Half vector distributed as D(h) (n.h) (Karis 2013, ImportanceSampleGGX).
vec3 ImportanceSampleGgx(vec2 xi, float alpha, mat3 frame) {
  float phi = 2.0 * kIblPi * xi.x;
  float cos_theta = sqrt((1.0 - xi.y) / (1.0 + (alpha * alpha - 1.0) * xi.y));
  float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
  return frame * vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// Mip level whose texels cover `sample_solid_angle` sr on a cube whose level
// 0 has face_size^2 texels a face (GPU Gems 3 ch. 20, eq. 13, with the cube's
// mean texel solid angle 4 pi / (6 N^2)), plus `bias`.
float FilteredLod(float sample_solid_angle, int face_size, int levels, float bias) {
  float texel_solid_angle = 4.0 * kIblPi / (6.0 * float(face_size) * float(face_size));
  float lod = 0.5 * log2(max(sample_solid_angle / texel_solid_angle, 1e-30)) + bias;
  return clamp(lod, 0.0, float(levels - 1));
}

// One entry of a level's GGX sample table (Karis 2013's PrefilterEnvMap with
// N = V = R, in the frame of n: z = n): xyz the direction l of sample i of n,
// w the source mip its filtered lookup reads; w < 0 marks a sample below the
// horizon of n (n.l <= 0), which the filter skips. Every texel of a level
// shares the table: with N = V the pdf and the mip depend on the sample
// alone, so they are computed once per level, not once per texel and sample.
// The estimate is the sum of L(frame(n) l) (n.l) over the table divided by
// the sum of (n.l) (PrefilterWithTable in ibl_prefilter.comp).
vec4 GgxSampleEntry(uint i, uint samples, float alpha, int face_size, int levels, float bias) {
  vec3 h = ImportanceSampleGgx(Hammersley(i, samples), alpha, mat3(1.0));
  float n_dot_h = h.z;
  vec3 l = 2.0 * n_dot_h * h - vec3(0.0, 0.0, 1.0);
  if (l.z <= 0.0) return vec4(0.0, 0.0, 1.0, -1.0);
  // pdf(l) = D(h) (n.h) / (4 (v.h)), and v.h = n.h when v = n.
  float pdf = DGgx(n_dot_h, alpha) * 0.25;
  return vec4(l, FilteredLod(1.0 / (float(samples) * pdf), face_size, levels, bias));
}

// Coarse grids (IBL_MODE_SPECULAR_GRID): a sample whose filtered lookup
// reads source mip m returns, as a function of the texel's direction, a
// signal that is bilinear between that mip's texels, 2^m source texels
// apart, so at level l (texels 2^l source texels apart) its lookups need
// not be taken at every texel: grid k, 2^k texels of the level apart, holds
// the sum over the samples with floor(m - l) = k (k = 0: the texels
// themselves; k at most `grids`), and each texel adds those sums bilinearly
// interpolated. A sample is thus never read on a grid coarser than its own
// mip's texels. With N = V the mip depends on the sample alone, so every
// texel of a level splits the table the same way.
int IblGridOf(float lod, int level, int grids) { return clamp(int(floor(lod - float(level))), 0, grids); }

// The number of coarse grids of a level of face_size texels: down to 2 x 2,
// at most IBL_MAX_GRIDS.
int IblGridCount(int face_size) { return clamp(findMSB(face_size) - 1, 0, IBL_MAX_GRIDS); }

// The Sun as a point source of irradiance E (at normal incidence) in
// direction s, through the same kernel as the GGX sample table: E (n.s) D(h) / 4 / W,
// W the kernel's normalization (the integral of (n.l) D(h) / 4 over n.l > 0,
// IblSunKernelNormalization in bake/gpu/ibl.cc). The kernel depends on n.s only
// and integrates to 1 over l, so it also integrates to 1 over n: the Sun's
// energy is kept, not clamped. Valid while the lobe is much wider than the
// disc (0.0047 rad): alpha >= 0.01 from the chain's second level on.
vec3 SunThroughGgx(vec3 n, vec3 s, vec3 irradiance, float alpha, float normalization) {
  float n_dot_s = dot(n, s);
  if (n_dot_s <= 0.0) return vec3(0.0);
  float n_dot_h = dot(n, normalize(n + s));
  return irradiance * (n_dot_s * DGgx(n_dot_h, alpha) * 0.25 / normalization);
}

// (1 / pi) times the irradiance on a surface of normal n: the radiance a
// white Lambertian surface reflects. Cosine-distributed samples, pdf (n.l)/pi,
// so the estimate is the mean of L.
vec3 FilterCosine(samplerCube source, vec3 n, uint samples, int face_size, int levels, float bias) {
  mat3 frame = FrameAround(n);
  vec3 sum = vec3(0.0);
  for (uint i = 0u; i < samples; ++i) {
    vec2 xi = Hammersley(i, samples);
    float phi = 2.0 * kIblPi * xi.x;
    float r = sqrt(xi.y);
    float n_dot_l = sqrt(max(0.0, 1.0 - xi.y));
    vec3 l = frame * vec3(r * cos(phi), r * sin(phi), n_dot_l);
    float pdf = max(n_dot_l, 1e-4) / kIblPi;
    float lod = FilteredLod(1.0 / (float(samples) * pdf), face_size, levels, bias);
    sum += textureLod(source, l, lod).rgb;
  }
  return sum / float(samples);
}

// Smith's geometry term with Schlick's approximation, k = alpha / 2 for
// image-based lighting (Karis 2013).
float GSmithSchlickIbl(float n_dot_v, float n_dot_l, float alpha) {
  float k = alpha * 0.5;
  return (n_dot_v / (n_dot_v * (1.0 - k) + k)) * (n_dot_l / (n_dot_l * (1.0 - k) + k));
}

// Karis 2013's IntegrateBRDF: the scale A and bias B of F0 in the split sum's
// second factor, A F0 + B = the integral of the GGX specular BRDF times (n.l)
// with Schlick's Fresnel, for view angle n.v and GGX alpha.
vec2 IntegrateDfg(float n_dot_v, float alpha, uint samples) {
  vec3 v = vec3(sqrt(max(0.0, 1.0 - n_dot_v * n_dot_v)), 0.0, n_dot_v);
  mat3 frame = mat3(vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0));
  vec2 ab = vec2(0.0);
  for (uint i = 0u; i < samples; ++i) {
    vec3 h = ImportanceSampleGgx(Hammersley(i, samples), alpha, frame);
    float v_dot_h = dot(v, h);
    vec3 l = 2.0 * v_dot_h * h - v;
    float n_dot_l = l.z;
    float n_dot_h = h.z;
    if (n_dot_l <= 0.0 || v_dot_h <= 0.0) continue;
    float g_vis = GSmithSchlickIbl(n_dot_v, n_dot_l, alpha) * v_dot_h / (n_dot_h * n_dot_v);
    float fc = pow(1.0 - v_dot_h, 5.0);
    ab += vec2((1.0 - fc) * g_vis, fc * g_vis);
  }
  return ab / float(samples);
}

#endif  // SKYBAKE_IBL_GLSL
