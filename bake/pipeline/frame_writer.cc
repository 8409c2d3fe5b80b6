#include "frame_writer.h"

#include <exception>

#include <fmt/format.h>

#include "bake_outputs.h"
#include "skybake/model/envmap.h"
#include "skybake/model/tonemap.h"
#include "skybake/output/cloud_shadow_file.h"
#include "skybake/output/ibl_files.h"
#include "skybake/output/sha256.h"
#include "skybake/pipeline/engine_files.h"
#include "skybake/pipeline/pass_plan.h"

namespace skybake {
namespace {

std::string FormatVector(const glm::dvec3& v) { return fmt::format("{:.9g} {:.9g} {:.9g}", v.x, v.y, v.z); }

// The frame's half-float scale: a single bake's from its brightest value, a
// sequence's checked against it. With the Sun as a light a sequence has no
// disc to fit and keeps scale 1: a frame whose own sky overflows (a very
// hazy aureole) gets a scale of its own, recorded in its files.
double FrameHalfScale(const FrameJob& job, bool sequence) {
  const SkyStyle& style = *job.plan->style;
  std::vector<const RgbaImage*> all;
  for (const RgbaImage& image : job.images) all.push_back(&image);
  const std::vector<RgbaImage> ibl_images = job.ibl ? IblImagesForRangeCheck(*job.ibl) : std::vector<RgbaImage>();
  for (const RgbaImage& image : ibl_images) all.push_back(&image);
  // Not the engine images: a preset never changes the scale of the bake's
  // own files (WriteEngineFiles gives them a smaller one when they need it).
  const double max_value = CheckedMaxValue(all);
  if (style.output.pixel_type != PixelType::kHalf) return job.half_scale;
  if (!sequence || style.output.sun == SunOutput::kLight) return HalfRangeScale(max_value, style.output.overflow);
  if (max_value * job.half_scale > kHalfMax)
    throw OutputError(
        fmt::format("frame {}: the brightest value {:.6g} exceeds the sequence's half-float scale {:.9g}: set "
                    "output.pixel_type = \"float\"",
                    job.plan->number, max_value, job.half_scale));
  return job.half_scale;
}

// Every EXR of the frame: its scale and provenance.
ExrWriteOptions FrameExrOptions(const FramePlan& plan, double half_scale) {
  const SkyStyle& style = *plan.style;
  ExrWriteOptions exr;
  exr.pixel_type = style.output.pixel_type;
  exr.compression = style.output.compression;
  exr.zip_level = style.output.zip_level;
  exr.scale = half_scale;
  const bool luminance = style.output.units == OutputUnits::kLuminance;
  if (luminance) exr.white_luminance = 1.0 / half_scale;
  exr.attributes = {
      {"skybake:version", SKYBAKE_VERSION},
      {"skybake:config", style.resolved_toml},
      {"skybake:source", style.source_path},
      {"skybake:units", luminance ? "linear Rec.709 luminance, cd/m^2 per 1.0 divided by skybake:scale"
                                  : "spectral radiance W m^-2 sr^-1 nm^-1 at 680/550/440 nm (R/G/B), "
                                    "divided by skybake:scale"},
      {"skybake:scale", fmt::format("{:.9g}", half_scale)},
      {"skybake:frame", "+Y up, North -Z, East +X; right-handed"},
      {"skybake:sun_direction", FormatVector(plan.sun)},
  };
  if (luminance) exr.attributes["skybake:color_space"] = "rec709";  // InOutputColorSpace names another
  if (plan.number > 0) exr.attributes["skybake:frame_number"] = std::to_string(plan.number);
  if (plan.time) exr.attributes["skybake:time"] = plan.time->Iso8601();
  return exr;
}

// The latlong among the frame's views (PlanViews order: faces, strip,
// latlong), when it renders one.
const RgbaImage* LatlongOf(const FrameJob& job) {
  const OutputSettings& o = job.plan->style->output;
  const size_t index = (o.faces ? 6 : 0) + (o.cube_strip ? 1 : 0);
  return index < job.images.size() ? &job.images[index] : nullptr;
}

// The views in the maps' colour space (output.color_space): Rec.709 as
// rendered, or converted copies with the EXR options saying so.
std::vector<RgbaImage> InOutputColorSpace(const FrameJob& job, ExrWriteOptions& exr) {
  const OutputColorSpace& space = job.plan->style->output.color_space;
  if (space.IsRec709()) return {};
  for (int i = 0; i < 8; ++i) exr.chromaticities[i] = float(space.chromaticities[i / 2][i % 2]);
  exr.attributes["skybake:units"] = space.description + " luminance, cd/m^2 per 1.0 divided by skybake:scale";
  exr.attributes["skybake:color_space"] = space.name;
  const Matrix3& m = space.from_rec709;
  std::vector<RgbaImage> converted;
  for (const RgbaImage& image : job.images) {
    RgbaImage c{image.width, image.height, std::vector<float>(image.texels() * 4), nullptr};
    const float* in = image.data();
    for (size_t t = 0; t < image.texels(); ++t) {
      for (int i = 0; i < 3; ++i)
        c.rgba[4 * t + i] = float(m[i][0] * in[4 * t] + m[i][1] * in[4 * t + 1] + m[i][2] * in[4 * t + 2]);
      c.rgba[4 * t + 3] = in[4 * t + 3];
    }
    converted.push_back(std::move(c));
  }
  return converted;
}

// The faces, strip and latlong EXRs encoded together in memory (their
// chunks shared among the threads), then each written atomically and
// checksummed from the same bytes.
std::vector<BakedFile> WriteViewExrs(const FrameJob& job, const ExrWriteOptions& frame_exr,
                                     const BakeOptions& options) {
  const OutputSettings& o = job.plan->style->output;
  const FrameNames& names = job.plan->names;
  ExrWriteOptions exr = frame_exr;
  const std::vector<RgbaImage> converted = InOutputColorSpace(job, exr);
  const std::vector<RgbaImage>& images = converted.empty() ? job.images : converted;
  std::vector<ExrFile> exrs;
  std::vector<std::string> kinds;
  size_t view_index = 0;
  if (o.faces) {
    for (int face = 0; face < 6; ++face, ++view_index) {
      ExrWriteOptions face_exr = exr;
      face_exr.attributes["skybake:cube_face"] = CubeFaceLabel(face);
      face_exr.attributes["skybake:face_orientation"] = "Vulkan cube map face (sc, tc) table";
      exrs.push_back({OutputPath(options, names.faces[face]), &images[view_index], face_exr});
      kinds.push_back("face");
    }
  }
  if (o.cube_strip) {
    ExrWriteOptions cube_exr = exr;
    cube_exr.envmap = 1;  // ENVMAP_CUBE
    exrs.push_back({OutputPath(options, names.cube), &images[view_index], cube_exr});
    kinds.push_back("cube");
  }
  if (o.latlong) {
    ExrWriteOptions latlong_exr = exr;
    latlong_exr.envmap = 0;  // ENVMAP_LATLONG
    exrs.push_back({OutputPath(options, names.latlong), &images[LatlongOf(job) - job.images.data()], latlong_exr});
    kinds.push_back("latlong");
  }
  const std::vector<std::string> encoded = EncodeExrs(exrs);
  // Each file on a thread of its own: most of a write is waiting for the
  // disk to confirm the fsync (about 1 ms a file here), which the files
  // can do together.
  std::vector<std::future<std::string>> checksums;
  for (size_t i = 0; i < exrs.size(); ++i)
    checksums.push_back(std::async(std::launch::async, [&, i] {
      WriteFileAtomically(exrs[i].name, encoded[i]);
      return Sha256OfText(encoded[i]);
    }));
  std::vector<BakedFile> files;
  std::exception_ptr failure;
  for (size_t i = 0; i < exrs.size(); ++i) {
    try {
      files.push_back({exrs[i].name, kinds[i], encoded[i].size(), checksums[i].get()});
    } catch (...) {
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
  return files;
}

// The IBL maps, with the frame's scale and provenance (ibl_files.h).
void WriteIblFiles(const FrameJob& job, const ExrWriteOptions& exr, const BakeOptions& options,
                   std::vector<BakedFile>& files) {
  const FrameNames& names = job.plan->names;
  const std::vector<std::string> ibl_files = EncodeIblFiles(*job.ibl, *job.plan->style, exr, names.with_dfg);
  for (size_t i = 0; i < ibl_files.size(); ++i) {
    const std::string path = OutputPath(options, names.ibl[i].name);
    WriteFileAtomically(path, ibl_files[i]);
    files.push_back({path, names.ibl[i].kind, ibl_files[i].size(), Sha256OfText(ibl_files[i])});
  }
}

// Preview (and glTF texture): exposure, ACES, sRGB; one exposure for a sequence.
void WritePreview(const FrameJob& job, const RgbaImage& latlong, const BakeOptions& options, WrittenFrame& w) {
  const SkyStyle& style = *job.plan->style;
  Clock::time_point preview_start = Clock::now();
  std::vector<float> display = DisplayLuminance(latlong.data(), latlong.texels(), style.output.units);
  if (!w.ev100) {
    w.ev100 = style.preview.auto_exposure ? AutoEv100(display, latlong.width, latlong.height) : style.preview.ev100;
    w.exposure_source = style.preview.auto_exposure ? "auto exposure" : "preview.ev100";
  }
  std::vector<uint8_t> srgb = TonemapToSrgb8(display, latlong.width, latlong.height, ExposureFromEv100(*w.ev100));
  std::string path = OutputPath(options, job.plan->names.png);
  uint64_t bytes = WritePng(path, latlong.width, latlong.height, srgb);
  w.files.push_back({path, style.output.preview ? "preview" : "gltf_texture", bytes, Sha256OfFile(path)});
  w.preview_seconds = SecondsSince(preview_start);
}

}  // namespace

WrittenFrame WriteFrameFiles(FrameJob& job, const RenderPlan& plan, const BakeOptions& options) {
  WrittenFrame w;
  const SkyStyle& style = *job.plan->style;
  Clock::time_point write_start = Clock::now();
  w.half_scale = FrameHalfScale(job, plan.sequence);
  const ExrWriteOptions exr = FrameExrOptions(*job.plan, w.half_scale);
  w.files = WriteViewExrs(job, exr, options);
  if (job.ibl) WriteIblFiles(job, exr, options, w.files);
  if (job.cloud_shadow_info)
    w.files.push_back(WriteCloudShadowFile(OutputPath(options, job.plan->names.cloud_shadow), job.cloud_shadow,
                                           *job.cloud_shadow_info, exr.attributes));
  if (!job.engine.empty()) {
    const std::vector<BakedFile> engine =
        WriteEngineFiles(style, job.engine, exr, options.out_dir, job.plan->names.engine);
    w.files.insert(w.files.end(), engine.begin(), engine.end());
  }
  w.exr_seconds = SecondsSince(write_start);
  w.exr_detail = fmt::format("{} files, {} compression{}, {}", w.files.size(), style.output.compression,
                             style.output.compression == "zip" || style.output.compression == "zips"
                                 ? fmt::format(" level {}", style.output.zip_level)
                                 : "",
                             style.output.pixel_type == PixelType::kHalf ? "half" : "float");
  w.ev100 = job.ev100;
  const RgbaImage* latlong = LatlongOf(job);
  if (latlong && WritesLatlongPng(style)) WritePreview(job, *latlong, options, w);
  w.write_seconds = SecondsSince(write_start);
  return w;
}

void FrameWriter::Write(FrameResult frame, FrameJob job) {
  Collect();
  job.half_scale = exposure_.half_scale;
  job.ev100 = exposure_.ev100;
  pending_.emplace(std::move(frame), std::async(std::launch::async, [this, job = std::move(job)]() mutable {
                     return WriteFrameFiles(job, plan_, options_);
                   }));
}

void FrameWriter::RecordVerified(FrameResult frame, std::vector<BakedFile> files) {
  Collect();
  frame.files = std::move(files);
  result_.preview_ev100 = exposure_.ev100.value_or(0.0);
  Record(std::move(frame));
}

void FrameWriter::Collect() {
  if (!pending_) return;
  Clock::time_point wait_start = Clock::now();
  WrittenFrame w = pending_->second.get();
  FrameResult frame = std::move(pending_->first);
  pending_.reset();
  const std::string preview_detail = w.ev100 ? fmt::format("EV100 {:.2f}, ACES filmic, sRGB", *w.ev100) : std::string();
  if (!plan_.sequence) {
    // A single bake waits for its files: the wait is the EXRs, then the preview.
    if (w.preview_seconds > 0.0) {
      timer_.Split("write EXR", w.exr_seconds, w.exr_detail);
      timer_.Finish("preview", preview_detail);
    } else {
      timer_.Finish("write EXR", w.exr_detail);
    }
  } else {
    if (SecondsSince(wait_start) > 0.005) timer_.Finish("waiting for files");
    timer_.Report("write EXR", w.exr_seconds,
                  w.exr_detail + fmt::format(", frame {}, beside the next frame's render", frame.number));
  }
  if (w.ev100) {
    if (!exposure_.ev100) exposure_.source = w.exposure_source;
    exposure_.ev100 = w.ev100;
    result_.preview_ev100 = *w.ev100;
    if (plan_.sequence && w.preview_seconds > 0.0) timer_.Report("preview", w.preview_seconds, preview_detail);
  }
  if (!plan_.sequence) {
    exposure_.half_scale = w.half_scale;
    result_.half_scale = w.half_scale;
  } else if (w.half_scale != exposure_.half_scale) {
    result_.half_scale = std::min(result_.half_scale, w.half_scale);  // a frame of its own scale (FrameHalfScale)
  }
  frame.files = std::move(w.files);
  frame.write_seconds = w.write_seconds;
  Record(std::move(frame));
}

void FrameWriter::Record(FrameResult frame) {
  manifest_.Add(frame);
  if (TimingsSpools* spools = timer_.spools()) {
    // Kept on disk, not in memory: a sequence's memory stays flat.
    spools->frames.Add(TimingsFrameText(frame));
    if (options_.frame_files) options_.frame_files(frame.files);
  } else {
    for (const BakedFile& f : frame.files) result_.files.push_back(f);
    result_.frames.push_back(std::move(frame));
  }
  // The manifest as frames are done: a killed bake leaves a valid record of them.
  manifest_.WriteProgress();
}

}  // namespace skybake
