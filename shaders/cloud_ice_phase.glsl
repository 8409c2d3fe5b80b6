// The phase function of cirrus ice crystals (docs/clouds.md "Cirrus"), in the
// common GLSL/C++ subset (glsl_prelude.glsl), after atmosphere.glsl (kPi):
// clouds.glsl calls it for the samples of a cirrus layer (SPEC_CLOUD_CIRRUS),
// and bake/model/shared_glsl.cc compiles it in double for the tests.
//
// Which: a two-term Henyey-Greenstein phase (Kattawar 1975, "A three-parameter
// analytic phase function for multiple scattering calculations", JQSRT 15,
// 839-849: p = w HG(g_f) + (1 - w) HG(g_b)), its asymmetry parameter
// g = w g_f + (1 - w) g_b set to 0.75, the asymmetry of the roughened-crystal
// ice models at visible wavelengths (Baum et al. 2011, "Improvements in
// shortwave bulk scattering and absorption models for the remote sensing of
// ice clouds", J. Appl. Meteor. Climatol. 50, 1037-1056: about 0.75 to 0.78
// at 0.65 um over effective diameters of 20 to 120 um for the general habit
// mixture; water clouds are near 0.85). The lobes are ours: a strong forward
// lobe g_f = 0.85 (diffraction and refraction through the crystals), a weak
// backward lobe g_b = -0.3 (the slight backscatter of roughened crystals),
// weighted w = (0.75 - g_b) / (g_f - g_b) = 1.05 / 1.15. No 22 deg halo: the
// roughened or complex crystals that make up most cirrus scatter without one
// (Baum et al. 2011 use roughened particles for that reason; ground observers
// see halos in a minority of cirrus, Sassen et al. 1994).
//
// Units: per steradian, normalised over the sphere (the integral of p over
// 4 pi sr is 1, tests/model/clouds_test.cc); cos_theta the cosine of the angle
// between the light's direction of travel and the scattered direction, as
// the clouds' water phase (CloudPhase).
#ifndef SKYBAKE_CLOUD_ICE_PHASE_GLSL
#define SKYBAKE_CLOUD_ICE_PHASE_GLSL

CONST_REAL kIcePhaseForwardG = 0.85;
CONST_REAL kIcePhaseBackwardG = -0.3;
CONST_REAL kIcePhaseForwardWeight = 1.05 / 1.15;  // so that g = 0.75

Real IcePhaseLobe(Real g, Real cos_theta) {
  Real denom = 1.0 + g * g - 2.0 * g * cos_theta;
  return (1.0 - g * g) / (4.0 * kPi * denom * sqrt(denom));
}

// Both lobes' g scaled by `eccentricity` (Wrenninge 2013's octave c^o; 1: the
// phase itself).
Real IceCrystalPhase(Real cos_theta, Real eccentricity) {
  return kIcePhaseForwardWeight * IcePhaseLobe(kIcePhaseForwardG * eccentricity, cos_theta) +
         (1.0 - kIcePhaseForwardWeight) * IcePhaseLobe(kIcePhaseBackwardG * eccentricity, cos_theta);
}

#endif  // SKYBAKE_CLOUD_ICE_PHASE_GLSL
