#include "skybake/pipeline/render_plan.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "skybake/input/engine_preset.h"
#include "skybake/input/frame_numbering.h"
#include "skybake/model/atmosphere.h"
#include "skybake/output/cloud_shadow_file.h"
#include "skybake/output/manifest.h"
#include "skybake/pipeline/pass_plan.h"

namespace skybake {

std::vector<std::string> FrameNames::All() const {
  std::vector<std::string> all = faces;
  for (const std::string* n : {&cube, &latlong})
    if (!n->empty()) all.push_back(*n);
  for (const IblFileName& n : ibl) all.push_back(n.name);
  if (!cloud_shadow.empty()) all.push_back(cloud_shadow);
  for (const std::string& n : engine) all.push_back(n);
  if (!png.empty()) all.push_back(png);
  return all;
}

std::vector<std::string> FrameNames::Kinds(const SkyStyle& style) const {
  std::vector<std::string> kinds(faces.size(), "face");
  if (!cube.empty()) kinds.push_back("cube");
  if (!latlong.empty()) kinds.push_back("latlong");
  for (const IblFileName& n : ibl) kinds.push_back(n.kind);
  if (!cloud_shadow.empty()) kinds.push_back("cloud_shadow");
  kinds.insert(kinds.end(), engine.size(), "engine");
  if (!png.empty()) kinds.push_back(style.output.preview ? "preview" : "gltf_texture");
  return kinds;
}

FrameNames FrameFileNames(const SkyStyle& style, int number_in_name, bool with_dfg, int number_width) {
  const OutputSettings& o = style.output;
  const std::string number = FrameNumberSuffix(number_in_name, number_width);
  FrameNames names;
  if (o.faces)
    for (int face = 0; face < 6; ++face) names.faces.push_back(o.basename + "_" + o.face_names[face] + number + ".exr");
  if (o.cube_strip) names.cube = o.basename + "_cube" + number + ".exr";
  if (o.latlong) names.latlong = o.basename + "_latlong" + number + ".exr";
  if (WritesLatlongPng(style)) names.png = o.basename + "_latlong" + number + ".png";
  names.ibl = IblFileNames(style, number_in_name, with_dfg, number_width);
  names.with_dfg = with_dfg;
  names.engine = EngineFileNames(style, number_in_name, number_width);
  if (style.cloud_shadow.enabled) names.cloud_shadow = CloudShadowFileName(o.basename, number_in_name, number_width);
  return names;
}

std::string FramePlan::Label() const { return number > 0 ? fmt::format("frame {}", number) : "render"; }

std::vector<const SkyStyle*> RenderPlan::styles() const {
  std::vector<const SkyStyle*> all;
  for (const FramePlan& f : frames) all.push_back(f.style);
  return all;
}

std::vector<SkyStyle> RenderPlan::BakedStyles() const {
  std::vector<SkyStyle> baked;
  for (const FramePlan& f : frames)
    if (Bakes(f)) baked.push_back(*f.style);
  return baked;
}

namespace {

// The decisions that follow from the frames: views, names, the reference
// frame, the files of this run.
RenderPlan Completed(RenderPlan plan) {
  // One width for every frame number of the sequence (its whole schedule's).
  int last_number = 0;
  for (const FramePlan& f : plan.frames) last_number = std::max(last_number, f.number);
  const int number_width = FrameNumberWidth(last_number);
  for (size_t i = 0; i < plan.frames.size(); ++i) {
    FramePlan& f = plan.frames[i];
    f.views = PlanViews(*f.style);
    f.names = FrameFileNames(*f.style, f.number, i == 0, number_width);
  }
  for (size_t i = 1; i < plan.frames.size(); ++i)
    if (plan.frames[i].elevation_deg > plan.frames[plan.reference].elevation_deg) plan.reference = i;
  for (const FramePlan& f : plan.frames) plan.exposed = plan.exposed || WritesLatlongPng(*f.style);
  plan.manifest_name = ManifestFileName(plan.part);
  // A part writes its own manifest and no scene (merge-manifest writes it).
  for (const FramePlan& f : plan.frames)
    if (plan.Bakes(f))
      for (const std::string& n : f.names.All()) plan.files.push_back(n);
  const SkyStyle& first = plan.first();
  if (first.gltf.enabled && !plan.part)
    for (const char* ext : {".gltf", ".bin", ".glb"}) plan.files.push_back(first.output.basename + ext);
  if (first.usd.enabled && !plan.part) plan.files.push_back(first.output.basename + ".usda");
  plan.files.push_back(plan.manifest_name);
  plan.files.push_back(TimingsFileName(plan.part));
  return plan;
}

}  // namespace

RenderPlan PlanSingleBake(const SkyStyle& style) {
  RenderPlan plan;
  FramePlan frame;
  frame.style = &style;
  frame.elevation_deg = style.sun.elevation_deg;
  frame.azimuth_deg = style.sun.azimuth_deg;
  frame.sun = SunDirectionFromElevationAzimuth(style.sun.elevation_deg, style.sun.azimuth_deg);
  plan.frames.push_back(frame);
  return Completed(std::move(plan));
}

RenderPlan PlanSequenceBake(const std::vector<SkyStyle>& styles, const Schedule& schedule,
                            const std::optional<FrameRange>& part) {
  if (styles.size() != schedule.frames.size() || styles.empty())
    throw std::invalid_argument(
        fmt::format("BakeSequence: {} styles for {} frames", styles.size(), schedule.frames.size()));
  if (part) {
    const FrameRange all = ScheduleFrameRange(schedule);
    if (!all.Contains(part->first) || !all.Contains(part->last) || part->count() < 1)
      throw std::invalid_argument(fmt::format("BakeSequence: frames {} to {} are not within the schedule's {} to {}",
                                              part->first, part->last, all.first, all.last));
  }
  RenderPlan plan;
  plan.schedule = &schedule;
  plan.sequence = true;
  plan.part = part;
  for (size_t i = 0; i < styles.size(); ++i) {
    const ScheduleFrame& f = schedule.frames[i];
    FramePlan frame;
    frame.style = &styles[i];
    frame.number = f.number;
    frame.time = f.time;
    frame.hours_from_start = f.hours_from_start;
    frame.elevation_deg = f.elevation_deg;
    frame.azimuth_deg = f.azimuth_deg;
    frame.sun = f.sun_direction;
    plan.frames.push_back(frame);
  }
  return Completed(std::move(plan));
}

}  // namespace skybake
