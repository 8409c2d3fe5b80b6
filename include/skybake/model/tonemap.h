// Display previews of HDR sky maps: exposure, then ACES filmic tone mapping,
// then the sRGB transfer function, to 8 bits.
#pragma once

#include <cstdint>
#include <vector>

namespace skybake {

// Narkowicz 2016, "ACES Filmic Tone Mapping Curve": a fit of the ACES RRT+ODT
// for sRGB displays, applied per channel to exposed linear values.
double AcesFilmic(double x);

// sRGB OETF (IEC 61966-2-1) of a linear value in [0, 1].
double SrgbEncode(double linear);

// Exposure from EV100 (ISO 100 camera, Lagarde & de Rousiers 2014 "Moving
// Frostbite to PBR"): exposure = 1 / (1.2 * 2^EV100), values in cd/m^2.
double ExposureFromEv100(double ev100);

// EV100 that maps the log-average luminance of the upper hemisphere of a
// latlong RGBA image (rows from the top) to the photographic mid grey 0.18
// after exposure, or a darker one when the lower hemisphere would then be
// exposed more than 1 stop above mid grey (a view from high altitude: the
// lit planet below a near-black sky). Texels brighter than 1e4 times the
// median (the sun disc) are left out of each average.
double AutoEv100(const std::vector<float>& latlong_rgba, int width, int height);

// Exposes, tone maps and encodes an RGBA float image to 8-bit sRGB RGB.
std::vector<uint8_t> TonemapToSrgb8(const std::vector<float>& rgba, int width, int height, double exposure);

}  // namespace skybake
