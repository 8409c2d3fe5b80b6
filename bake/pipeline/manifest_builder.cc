#include "manifest_builder.h"

#include "skybake/base/file_door.h"

#include <algorithm>
#include <filesystem>

#include "bake_outputs.h"
#include "skybake/output/sha256.h"

namespace skybake {

ManifestBuilder::ManifestBuilder(const RenderPlan& plan, const BakeOptions& options, const BakeExposure& exposure,
                                 BakeResult& result)
    : plan_(plan),
      options_(options),
      exposure_(exposure),
      result_(result),
      spool_(options.out_dir),
      written_(Clock::now()) {
  std::string sequence_identity;
  for (size_t i = 0; i < plan.frames.size(); ++i) {
    const FramePlan& frame = plan.frames[i];
    style_sha256_.push_back(Sha256OfText(frame.style->resolved_toml));
    sequence_identity +=
        SequenceIdentityLine(frame.number, frame.time ? frame.time->Iso8601() : "", frame.sun, style_sha256_.back());
    frame_index_[frame.number] = i;
  }
  sequence_sha256_ = Sha256OfText(sequence_identity);
  keeps_scene_frames_ = !plan.part && (plan.first().gltf.enabled || plan.first().usd.enabled);
  result_.manifest_path = OutputPath(options_, plan_.manifest_name);
}

Manifest ManifestBuilder::Head() const {
  const SkyStyle& first = plan_.first();
  const Schedule* schedule = plan_.schedule;
  Manifest m;
  m.version = SKYBAKE_VERSION;
  m.commit = options_.build_commit;
  m.style = first.source_path;
  m.schedule = schedule ? schedule->source_path : "";
  m.sequence_sha256 = sequence_sha256_;
  m.units = first.output.units == OutputUnits::kLuminance ? "luminance cd/m^2 (sky), lux (irradiance)"
                                                          : "spectral W m^-2 sr^-1 nm^-1 at 680/550/440 nm";
  m.exposure_ev100 = exposure_.ev100.value_or(0.0);
  m.exposure_source = exposure_.source;
  const FramePlan& reference = plan_.frames[plan_.reference];
  m.texture_frame = reference.number;
  m.half_scale = exposure_.half_scale;
  if (schedule) {
    m.place = schedule->place;
    m.sequence = FrameRange{plan_.frames.front().number, plan_.frames.back().number};
  }
  m.part = plan_.part;
  // The scene's texture: the reference frame's PNG, a 2h x h latlong.
  const SkyStyle& ref = *reference.style;
  m.gltf = {first.gltf.enabled,  first.output.basename,         first.gltf,
            reference.names.png, 2 * ref.render.latlong_height, ref.render.latlong_height};
  if (first.usd.enabled) m.usd = {true, first.output.basename};
  return m;
}

void ManifestBuilder::Add(const FrameResult& f) {
  const size_t i = frame_index_.at(f.number);
  ManifestFrame frame = ManifestFrameOf(f);
  frame.style_sha256 = style_sha256_[i];
  frame.hours_from_start = plan_.frames[i].hours_from_start;
  frame.animation_time_s = plan_.schedule && plan_.schedule->clock_times ? plan_.frames[i].hours_from_start : double(i);
  if (plan_.first().usd.enabled)
    frame.sun_angular_radius_rad = plan_.frames[i].style->atmosphere.sun_angular_radius_rad;
  spool_.Add(ManifestFrameText(frame));
  if (!keeps_scene_frames_) return;
  // The scene keeps of the frames what it reads (WriteScene): the texture
  // frame's files; with the USD layer every frame's latlong and style hash.
  const bool usd = plan_.first().usd.enabled;
  if (!usd) frame.style_sha256 = {};
  if (frame.number != plan_.frames[plan_.reference].number)
    std::erase_if(frame.files, [&](const ManifestFile& file) { return !usd || file.kind != "latlong"; });
  scene_frames_.push_back(std::move(frame));
}

void ManifestBuilder::Write(bool complete) {
  Manifest m = Head();
  m.complete = complete;
  WriteJsonWithSpools(result_.manifest_path, ManifestText(m), {{"frames", &spool_}});
  ++result_.manifest_writes;
  result_.manifest_bytes_written += WrittenFileSize(result_.manifest_path);
}

std::vector<BakedFile> ManifestBuilder::WriteSceneAndManifest() {
  Manifest m = Head();
  m.frames = std::move(scene_frames_);
  scene_frames_ = {};
  std::vector<BakedFile> scene_files = WriteScene(m, options_.out_dir);
  m.frames.clear();
  m.complete = true;
  WriteJsonWithSpools(result_.manifest_path, ManifestText(m), {{"frames", &spool_}});
  return scene_files;
}

// A write costs time in proportion to the frames done, so rewriting the
// manifest after every frame grew as frames squared. It is rewritten after
// a frame when the frames done have grown by a tenth since its last write
// (so after each of the first twenty; the bytes written add up to about 11
// times the final manifest), or when kManifestSeconds have passed since
// the last write and at least kManifestSpacing times what it took (writes
// stay under a tenth of the bake). Both keep the cost linear; a killed
// bake loses at most the frames since the last write (--resume bakes them
// again).
void ManifestBuilder::WriteProgress() {
  constexpr double kManifestSpacing = 9.0;
  constexpr double kManifestSeconds = 30.0;
  const size_t done = spool_.size();
  if (done - written_frames_ < std::max<size_t>(1, written_frames_ / 10) &&
      SecondsSince(written_) < std::max(kManifestSeconds, kManifestSpacing * write_seconds_))
    return;
  const Clock::time_point start = Clock::now();
  Write(false);
  written_frames_ = done;
  written_ = Clock::now();
  write_seconds_ = std::chrono::duration<double>(written_ - start).count();
}

}  // namespace skybake
