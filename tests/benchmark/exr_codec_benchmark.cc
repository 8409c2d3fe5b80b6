// The codec study behind output.compression, output.zip_level and
// output.pixel_type: one W1 frame of the default style (six 512^2 faces, the
// 512 x 3072 strip, a 2048 x 1024 latlong; docs/performance.md) is rendered
// once on the Vulkan device, then encoded in memory by every lossless codec,
// zip level and pixel type, on 1 and on 2 threads: by skybake's libdeflate
// encoder (none, zips, zip: the `encode/` rows) and by OpenEXR's own encoder
// (every codec: the `openexr/` rows). Reports the median encode time of the
// frame's eight files (encoded together, as a bake does: EncodeExrs) and their total size; writing to disk is timed
// separately (`write+fsync` rows) since it depends on the disk.
// `--sun-elevation-deg=E` renders the frame with the Sun at E degrees instead
// of the style's (a twilight or night frame of a time-lapse: -6, -30).
//
//   build/tests/exr_codec_benchmark [--sun-elevation-deg=E] [--benchmark_repetitions=N]
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "skybake/input/config.h"
#include "skybake/output/exr_io.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/gpu/vulkan_context.h"

namespace {

using namespace skybake;

std::optional<double> g_sun_elevation_deg;  // --sun-elevation-deg

// The W1 frame's images, rendered once.
const std::vector<RgbaImage>& W1Images() {
  static const std::vector<RgbaImage> images = [] {
    ConfigResult config = LoadSkyStyle(std::string(SKYBAKE_SOURCE_DIR) + "/configs/default.toml",
                                       {"render.cube_size=512", "render.latlong_height=1024"});
    if (!config.ok()) throw std::runtime_error("configs/default.toml does not parse");
    const SkyStyle& style = config.style;
    VulkanContext context{VulkanOptions{}};
    SkyRenderer renderer(context, StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                         OutputScale(style.output.units), false,
                         ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)));
    std::vector<ViewRequest> views = PlanViews(style);
    std::vector<std::vector<float>> pixels = renderer.Render(
        SunDirectionFromElevationAzimuth(g_sun_elevation_deg.value_or(style.sun.elevation_deg), style.sun.azimuth_deg),
        views);
    std::vector<RgbaImage> out;
    for (size_t i = 0; i < views.size(); ++i) out.push_back({views[i].width, views[i].height, std::move(pixels[i])});
    return out;
  }();
  return images;
}

double W1HalfScale() {
  std::vector<const RgbaImage*> all;
  for (const RgbaImage& image : W1Images()) all.push_back(&image);
  return HalfRangeScale(CheckedMaxValue(all), OverflowPolicy::kScale);
}

void BM_Encode(benchmark::State& state, PixelType type, std::string compression, int level, bool openexr) {
  const std::vector<RgbaImage>& images = W1Images();
  SetExrThreads(int(state.range(0)));
  ExrWriteOptions options;
  options.pixel_type = type;
  options.compression = compression;
  options.zip_level = level;
  options.openexr_encoder = openexr;
  options.scale = type == PixelType::kHalf ? W1HalfScale() : 1.0;
  size_t bytes = 0, texels = 0;
  // The frame's files together, as a bake encodes them (EncodeExrs).
  std::vector<ExrFile> files;
  for (const RgbaImage& image : images) files.push_back({"w1.exr", &image, options});
  for (auto _ : state) {
    bytes = 0;
    texels = 0;
    for (const std::string& file : EncodeExrs(files)) bytes += file.size();
    for (const RgbaImage& image : images) texels += size_t(image.width) * image.height;
  }
  const double channel = type == PixelType::kHalf ? 2.0 : 4.0;
  state.counters["MB_written"] = double(bytes) * 1e-6;
  state.counters["ratio"] = double(texels) * 3.0 * channel / double(bytes);
  state.counters["raw_MB_per_s"] =
      benchmark::Counter(double(texels) * 3.0 * channel * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}

// Atomic writes (temporary, fsync, rename) of the frame's files, already
// encoded with the default codec: what the disk adds.
void BM_WriteFsync(benchmark::State& state, PixelType type) {
  const std::vector<RgbaImage>& images = W1Images();
  SetExrThreads(2);
  ExrWriteOptions options;
  options.pixel_type = type;
  options.scale = type == PixelType::kHalf ? W1HalfScale() : 1.0;
  std::vector<std::string> encoded;
  size_t bytes = 0;
  for (const RgbaImage& image : images) {
    encoded.push_back(EncodeExr("w1.exr", image, options));
    bytes += encoded.back().size();
  }
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "skybake_codec_bench";
  std::filesystem::create_directories(dir);
  for (auto _ : state)
    for (size_t i = 0; i < encoded.size(); ++i)
      WriteFileAtomically((dir / fmt::format("f{}.exr", i)).string(), encoded[i]);
  std::filesystem::remove_all(dir);
  state.counters["MB_written"] = double(bytes) * 1e-6;
  state.counters["files"] = double(encoded.size());
}

void Register() {
  struct Codec {
    bool openexr;
    const char* name;
    int level;
  };
  const Codec codecs[] = {{false, "none", 0}, {false, "zips", 1}, {false, "zips", 2}, {false, "zip", 1},
                          {false, "zip", 2},  {false, "zip", 3},  {false, "zip", 4},  {false, "zip", 6},
                          {false, "zip", 9},  {true, "none", 0},  {true, "rle", 0},   {true, "zips", 1},
                          {true, "zip", 1},   {true, "zip", 4},   {true, "piz", 0}};
  for (PixelType type : {PixelType::kHalf, PixelType::kFloat}) {
    const char* type_name = type == PixelType::kHalf ? "half" : "float";
    for (const Codec& c : codecs) {
      const char* encoder = c.openexr ? "openexr" : "encode";
      std::string name = c.level > 0 ? fmt::format("{}/{}/{}/level{}", encoder, type_name, c.name, c.level)
                                     : fmt::format("{}/{}/{}", encoder, type_name, c.name);
      benchmark::RegisterBenchmark(name.c_str(), BM_Encode, type, std::string(c.name), std::max(c.level, 1), c.openexr)
          ->Arg(1)
          ->Arg(2)
          ->ArgName("threads")
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->MinTime(0.5);
    }
    benchmark::RegisterBenchmark(fmt::format("write+fsync/{}/zip/level{}", type_name, kDefaultZipLevel).c_str(),
                                 BM_WriteFsync, type)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->MinTime(0.5);
  }
}

}  // namespace

int main(int argc, char** argv) {
  KeepFrameMemoryInHeap();  // as the CLI does
  const std::string flag = "--sun-elevation-deg=";
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]).rfind(flag, 0) == 0)
      g_sun_elevation_deg = std::stod(std::string(argv[i]).substr(flag.size()));
    else argv[kept++] = argv[i];
  }
  argc = kept;
  Register();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
