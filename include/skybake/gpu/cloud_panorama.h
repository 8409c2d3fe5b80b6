// The cloud panorama: the clouds of a frame marched once, into one latlong
// of cloud radiance and transmittance, and resampled into every view of the
// frame (docs/clouds.md, "Speed"). The views of a bake look along the same
// directions from the same observer (six faces, the cube strip and the
// latlong: 5.24 Mtexels for W3), so marching each of them repeats the same
// work; the panorama marches the directions of the finest view once.
//
// The panorama's texel grid is the OpenEXR latlong's (Imf::LatLongMap: row 0
// the zenith, column 0 and column width - 1 the same meridian), but a row
// marches only width x cos(latitude) + 1 of its texels, spread over the
// whole circle (CloudPanoramaRowWidth): the same angular resolution as the
// equator's, about a third fewer texels over a hemisphere. A latlong view of
// the panorama's size reads its whole rows' texels, bit for bit what marching
// that view gives, and the narrower rows along the row; the other views read
// it bilinearly.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "skybake/gpu/sky_renderer.h"

namespace skybake {

struct CloudPanorama {
  int width = 0;  // 0: no panorama, every view marches its own texels
  int height = 0;
  size_t texels() const { return size_t(width) * size_t(height); }
};

// The latlong height whose angular texel spacing matches the finest of `view`:
// its own height for a latlong, ceil(pi / 2 x face size) for a cube view (a
// face's texels are 2 / N rad apart at its centre, a latlong's pi / H); 0 for
// a view of explicit directions (never resampled).
int CloudPanoramaHeightFor(const ViewRequest& view);

// The panorama of a frame's views: height = ceil(scale x the finest view's
// height above), width = 2 x height. None (width 0) when scale is 0, when
// a view of explicit directions is among them, when it would not be cheaper
// than marching the views (its texels more than 2/3 of theirs: a bake of one
// latlong view marches it), or when it would exceed kMaxCloudPanoramaHeight.
CloudPanorama ChooseCloudPanorama(const std::vector<ViewRequest>& views, double scale);

// The rows [begin, end) of a panorama whose rays can meet a cloud band; the
// others hold no cloud (radiance 0, transmittance 1), are not marched, and
// the resample reads them as such. From below every band (the ground's
// observer), the rays that meet the ground first see no cloud: the rows more
// than kCloudPanoramaRowMargin below the horizon's cosine. From above every
// band, the rays that rise see none: the rows more than the margin above the
// horizontal. From inside a band, every row. `bands`: the bands' bottom and
// top altitudes, km (GpuClouds.bands); radii in km.
struct CloudPanoramaRows {
  int begin = 0;
  int end = 0;
};
CloudPanoramaRows CloudPanoramaRowsSeeingBands(const CloudPanorama& panorama, double bottom_radius_km,
                                               double observer_altitude_km,
                                               const std::vector<std::array<double, 2>>& bands);
// In cosine of the zenith angle: 0.02 keeps the marched rows' rays clear of
// the ground's tangent by a kilometre or more (float rounding at 6360 km is
// half a metre), so a row left out is one the march would leave empty too.
constexpr double kCloudPanoramaRowMargin = 0.02;

// The texels row y of `panorama` marches (cloud_panorama.glsl): one more
// than width x cos(latitude), at least CLOUD_PANORAMA_MIN_ROW_WIDTH, at most
// the width; and the texels the rows [begin, end) march in all.
int CloudPanoramaRowWidth(const CloudPanorama& panorama, int y);
size_t CloudPanoramaMarchedTexels(const CloudPanorama& panorama, const CloudPanoramaRows& rows);

// The stride of the order in which the panorama's n blocks of marched rows
// run (cloud_panorama.glsl, CloudPanoramaRowBlock: workgroup row g marches
// block g x stride mod n): the first integer from 0.618 n on that is coprime
// with n, so g -> g x stride mod n is a permutation and any run of
// consecutive groups holds rows from all over the marched range. lavapipe
// deals a dispatch's groups out to its threads in runs of consecutive
// groups, and the rows near the horizon cost several times the rows near
// the zenith: in row order one thread took the costly rows.
int CloudPanoramaBlockStride(int blocks);

// 4096 x 2048 texels of RGBA float: 128 MiB.
constexpr int kMaxCloudPanoramaHeight = 2048;

}  // namespace skybake
