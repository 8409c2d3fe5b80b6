// The GPU sky renderer: builds the transmittance and multiple-scattering LUTs
// once per atmosphere, then renders any number of output views (latlong,
// cube strip, Vulkan cube faces, explicit directions) per sun position, all
// views of a frame in one submission. Each pass is timed with GPU timestamps.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/aoas.h"
#include "skybake/model/atmosphere.h"
#include "skybake/model/colour_conversion.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/model/clouds.h"
#include "skybake/model/view.h"
#include "skybake/gpu/pass_timing.h"
#include "skybake/gpu/vulkan_context.h"

namespace skybake {

class SpectralSky;     // spectral_sky.h
struct CloudPanorama;  // cloud_panorama.h

// Texels [x0, x1) x [y0, y1) of a view.
struct TexelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// Rectangles, disjoint, that hold every texel of `view` whose direction is
// within `angle` radians of unit `direction`: tiles of 16 x 16 texels whose
// centre is within `angle` plus 1.5 times the tile's own angular radius (the
// largest angle from its centre to a corner), joined along each row of
// tiles. Every texel of a MAPPING_DIRECTIONS view.
std::vector<TexelRect> TexelsNearDirection(const ViewRequest& view, const glm::dvec3& direction, double angle);

// Diagnostic switches of the shaders. The CLI sets them from the environment
// (README "Shaders"), read once in main; the library never reads it.
struct ShaderSwitches {
  bool generic = false;       // SKYBAKE_GENERIC_SHADERS=1: every pipeline from the generic shaders, no variant
  bool sun_disc_pass = true;  // SKYBAKE_SUN_DISC_PASS=0: the disc tested by every texel, no pass of its own
  // SKYBAKE_SHADOWED_CLOUDS=0: no cloud pass without the Sun's light march, even with every band in the
  // Earth's shadow (CloudEarthShadowElevationDeg)
  bool shadowed_clouds = true;
  // SKYBAKE_TWILIGHT_ROWS=0: a twilight frame's views wholly with the twilight pipeline, not only the rows
  // that can hold a marched texel (SkyRenderer::TwilightRows)
  bool twilight_rows = true;
  // SKYBAKE_TEXEL_VIEWS=0: the shaders read the LUTs, the cloud noise and the cloud tables from their
  // storage buffers, not through the texel views (SPEC_TEXEL_VIEWS), as on a device whose texel buffers
  // are too small for them
  bool texel_views = true;
  // SKYBAKE_FORMATION_READ=1: the cloud pipelines keep a formation's density read (SPEC_CLOUD_FORMATION)
  // even when no layer has one, as the generic build did
  bool formation_read_always = false;
  // Twilight frames whose half-float views the march would not change go unmarched (pipeline/twilight_skip.h);
  // off unless asked for (the CLI: SKYBAKE_TWILIGHT_SKIP=1): its probes cost more than they save on W2
  bool twilight_skip = false;
};

// Whether the sun disc is added by a pass of its own over the texels near
// the Sun (SkyRenderer::Render) rather than tested by every texel of the sky
// pass: with the sky-view LUT and none of the AOAS principles that act on
// the disc after it is added (ambiguity, clouds), unless shaders.sun_disc_pass
// is off.
bool UsesSunDiscPass(const QualitySettings& quality, const EffectSettings& effects, const AoasSwitches& aoas,
                     const ShaderSwitches& shaders = ShaderSwitches());

// Where each pipeline's SPIR-V comes from: the variants compiled with the
// presets' quality fixed and optimized by glslang -Os (CMakeLists.txt), when the
// settings match them and shaders.generic is off; else the generic shaders,
// specialized when the pipeline is created.
struct ShaderSources {
  bool analytic_luts = false;    // LUT shaders from the analytic-integrator variants
  bool sky_view_render = false;  // sky_render from the sky-view variant
};
ShaderSources ChooseShaderSources(const QualitySettings& quality, bool skydome,
                                  const ShaderSwitches& shaders = ShaderSwitches());

// Views rendered in place (SkyRenderer::RenderInPlace): RGBA float texels,
// rows from the top, in the renderer's host-visible memory. The memory stays
// unchanged while any copy of `hold` lives, and only that long.
struct RenderedViews {
  std::vector<const float*> views;  // one per requested view
  std::shared_ptr<const void> hold;
};

class SkyRenderer {
 public:
  // With `output_directions`, views contain the unit direction of each texel
  // (xyz) instead of radiance: the shader-side mapping, for tests. `aoas`
  // holds the per-texel aesthetic principles (none by default); the hue
  // principle is already in `atmosphere` (StyledAtmosphere).
  // With quality.wavelengths above 3 it is the spectral mode (spectral_sky.h):
  // views are linear Rec.709 in cd/m^2 and `output_scale` is not used.
  SkyRenderer(VulkanContext& context, const AtmosphereParams& atmosphere, const QualitySettings& quality,
              const EffectSettings& effects, const Rgb& output_scale, bool output_directions = false,
              const AoasInputs& aoas = AoasInputs(), const CloudInputs& clouds = CloudInputs(),
              const ShaderSwitches& shaders = ShaderSwitches());
  ~SkyRenderer();
  SkyRenderer(const SkyRenderer&) = delete;
  SkyRenderer& operator=(const SkyRenderer&) = delete;

  // The spectral mode's style pass (SpectralSky): a renderer with no sky of
  // its own, whose one pipeline (sky_style.comp) applies the principles that
  // act on a texel's colour (the AOAS saturation clouds and shapes, the
  // night floor; StyleSkyRadiance of aoas.glsl) to views of colour that
  // `output_scale` maps radiance to, as the sky pass of the three-wavelength
  // path applies them to its radiance.
  static std::unique_ptr<SkyRenderer> StylePass(VulkanContext& context, const AtmosphereParams& atmosphere,
                                                const QualitySettings& quality, const EffectSettings& effects,
                                                const Rgb& output_scale, const AoasInputs& aoas);
  // StylePass only: styles `images` (RGBA texels of `views`) in place. A
  // MAPPING_DIRECTIONS view takes its texels' unit directions from `directions`.
  void ApplyStyle(const glm::dvec3& sun_direction, const std::vector<ViewRequest>& views,
                  std::vector<std::vector<float>>& images, const std::vector<glm::dvec3>& directions = {});

  // Builds the transmittance LUT, then the multiple-scattering LUT (only when
  // multiple scattering is on). Called automatically by the first Render.
  void PrecomputeLuts();

  // Renders every view for the sun direction (unit, towards the Sun) and
  // returns one RGBA float image per view, rows from the top.
  // With `sun_disc` false, the same pipeline renders without the disc (a
  // push constant), from the same LUTs.
  std::vector<std::vector<float>> Render(const glm::dvec3& sun_direction, const std::vector<ViewRequest>& views,
                                         bool sun_disc = true);

  // Render without the copy: the texels stay where the device wrote them,
  // for as long as the result's `hold` lives (a bake's writer thread reads
  // them while the next frame renders into other memory). Must be called on
  // the renderer's thread; `hold` may be released on any thread. The
  // renderer must outlive every `hold`.
  RenderedViews RenderInPlace(const glm::dvec3& sun_direction, const std::vector<ViewRequest>& views,
                              bool sun_disc = true);

  // A frame in two steps, for the spectral mode's style pass (SpectralSky)
  // to act on the sky behind the cloud layers as the three-wavelength sky
  // pass does: RenderClearSky renders the views (or one MAPPING_DIRECTIONS
  // view of `directions`) without their cloud pass, into the renderer's
  // output buffer, and returns where each view's RGBA texels are there,
  // writable; CompositeClouds then runs the cloud pass of those views over
  // what the texels hold by then, as Render runs it over the sky pass's
  // (the clouds' light plus their transmittance times the texel). The
  // texels stay until the renderer's next call. Without cloud layers,
  // CompositeClouds leaves them as they are.
  std::vector<float*> RenderClearSky(const glm::dvec3& sun_direction, const std::vector<ViewRequest>& views,
                                     bool sun_disc, const std::vector<glm::dvec3>& directions = {});
  void CompositeClouds();

  // True while the texels of a RenderInPlace are held.
  bool HoldsFrames() const;

  // Radiance (RGBA) along each unit direction.
  std::vector<float> RenderDirections(const glm::dvec3& sun_direction, const std::vector<glm::dvec3>& directions,
                                      bool sun_disc = true);

  // Replaces the atmosphere (a scheduled drift of its constants, say)
  // without new pipelines: the LUTs are rebuilt by the next Render. False
  // when the shader variant or a LUT size would change (a new renderer is
  // needed).
  bool UpdateAtmosphere(const AtmosphereParams& atmosphere, const QualitySettings& quality,
                        const EffectSettings& effects, const Rgb& output_scale);

  // The output conversion of the next renders (colour_conversion.h): sky
  // texels through `conversion.sky`, direct sunlight (the disc, sunlit clouds
  // and ground) through `conversion.direct`. Until the first call, and after
  // UpdateAtmosphere keeps it, every path gets the constructor's
  // `output_scale`. The LUTs hold radiance and stay. The spectral mode
  // integrates its bins and ignores it.
  void SetOutputConversion(const OutputConversion& conversion);

  // Replaces the per-texel AOAS parameters (drift, strengths, shapes) without
  // touching the LUTs or pipelines; false when the switches differ (a new
  // shader variant is needed).
  bool UpdateAoas(const AoasInputs& aoas);

  // Replaces the cloud layers' parameters (the wind's offsets of a new
  // frame, say) without new pipelines; the noise volumes are generated again
  // only when their seeds or weather images change. False when the layer
  // count or a noise size differs (a new renderer is needed).
  bool UpdateClouds(const CloudInputs& clouds);

  // The cloud shadow map (cloud_shadow.h): resolution^2 transmittances,
  // row 0 north; zeros when the Sun's centre is at or below the horizon,
  // ones without cloud layers. Defined in bake/gpu/cloud_shadow_render.cc.
  std::vector<float> RenderCloudShadow(const glm::dvec3& sun_direction, const CloudShadowSettings& shadow);

  // The noise buffer of the cloud layers (shape, detail, weather per layer),
  // for tests; empty without clouds.
  std::vector<float> ReadCloudNoise() const;
  // LUT contents (RGBA float per texel, row-major), for tests.
  std::vector<float> ReadTransmittanceLut() const;
  std::vector<float> ReadMultipleScatteringLut() const;

  const std::vector<PassTiming>& last_timings() const { return timings_; }
  const RenderCounters& counters() const { return counters_; }
  // Whether the renders that follow may march the twilight band (on unless
  // switched off here): the bake switches it off for the views of a frame
  // whose every texel rounds to 0 in half floats either way
  // (pipeline/twilight_skip.h), and on again after them.
  void set_twilight_march(bool on) { twilight_march_allowed_ = on; }
  bool twilight_march_allowed() const { return twilight_march_allowed_; }
  // Whether a frame with this Sun would march the twilight band (with the march allowed).
  bool MarchesTwilight(const glm::dvec3& sun) const;
  // Whether the shaders read through the texel views (SPEC_TEXEL_VIEWS).
  bool reads_texel_views() const { return texel_views_whole_; }

 private:
  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    VkDeviceSize size = 0;
  };
  // Memory of a frame rendered in place; free when `hold` has no other owner.
  struct FrameSlot {
    Buffer buffer;
    std::shared_ptr<int> hold;
  };
  struct Dispatch {
    std::string name;
    VkPipeline pipeline;
    gpu::SkyPush push;
    uint32_t groups_x, groups_y;
    bool continues = false;  // more of the previous dispatch's pass: timed together with it
  };

  // What SubmitViews submits: the whole frame, or the frame without its
  // cloud pass and then that pass alone (RenderClearSky, CompositeClouds).
  enum class FramePart { kWhole, kClearSky, kClouds };
  struct ClearSkyFrame {
    glm::dvec3 sun;
    std::vector<ViewRequest> views;
    bool sun_disc;
    std::vector<size_t> offsets;
  };
  enum class Role { kSky, kStylePass };
  SkyRenderer(Role role, VulkanContext& context, const AtmosphereParams& atmosphere, const QualitySettings& quality,
              const EffectSettings& effects, const Rgb& output_scale, bool output_directions, const AoasInputs& aoas,
              const CloudInputs& clouds, const ShaderSwitches& shaders);
  void CreateDescriptorSet();  // the layouts, the pool and the set of kBindingCount bindings
  // The pipelines the style's effects need, compiled on one thread each (the constructor's).
  void CompilePipelines(const QualitySettings& quality, const EffectSettings& effects, const AoasSwitches& aoas,
                        const ShaderSwitches& shaders);
  void CreateCommandObjects();  // the command pool, its one command buffer and the fence

  Buffer CreateBuffer(VkDeviceSize size, VkBufferUsageFlags usage);
  // The texel view of binding BINDING_CLOUD_NOISE_TEXELS + i over its buffer,
  // made again (after its buffer was), its descriptor not written.
  void CreateTexelView(int i);
  struct TexelRange {
    const Buffer* buffer;
    VkFormat format;
    VkDeviceSize texel_bytes, texels;
  };
  TexelRange TexelViewRange(int i) const;
  void DestroyBuffer(Buffer& buffer);
  void EnsureOutputCapacity(VkDeviceSize bytes);
  void EnsureCloudLutCapacity(size_t texels);      // the cloud tables and the panorama after them
  void EnsureDispatchCapacity(size_t dispatches);  // room for a submission's SkyPush constants
  void UpdateDescriptors();
  // Points one storage-buffer binding of the descriptor set at `buffer`.
  void WriteStorageBinding(uint32_t binding, VkBuffer buffer);
  // `sun_disc`, `sun_disc_pass`: specialization constants 1 and 15.
  VkPipeline CreatePipeline(const uint32_t* code, size_t bytes, bool sun_disc, bool sun_disc_pass,
                            bool twilight_march = false, bool cloud_sun_light = true, bool cloud_light_volume = false);
  // The cloud pass with every light sample marched, for a frame whose Sun is
  // too low for the light volume (CloudLightVolumeForSun); built on first use.
  VkPipeline MarchedLightCloudPipeline();
  // The frame's light volume (CLOUD_PASS_LIGHT_VOLUME), unless it holds this Sun
  // and these clouds already.
  // One dispatch of the cloud table pipeline (CLOUD_PASS_*) over a width x
  // height grid of texels.
  void AddCloudLutDispatch(const char* name, int32_t pass, const glm::dvec3& sun, int width, int height,
                           std::vector<Dispatch>& dispatches);
  void AddCloudLightVolume(const glm::dvec3& sun, std::vector<Dispatch>& dispatches, std::vector<bool>& barriers);
  // Whether this Sun makes the frame twilight (TwilightSunElevationDeg): its
  // views march the twilight band (quality.twilight_march_band_deg) and read
  // the sun transmittance in the logarithm, with the sky pass that does,
  // built on the first such frame.
  bool MarchesTwilightBand(const glm::dvec3& sun) const;
  VkPipeline TwilightSkyPipeline();
  // The runs of `view`'s rows that a twilight frame renders with the twilight
  // pipeline: those that may hold a texel with TwilightMarchWeight above 0
  // (between TwilightMarchElevations, widened by 1e-3 rad for float32's
  // rounding), grown to whole workgroups. The day pipeline gives the other
  // rows the same bytes without the march's masked cost. Computed once per
  // view shape.
  const std::vector<RowRange>& TwilightRows(const ViewRequest& view);
  // The sky pass over one view (`view_dispatch`, ViewDispatches): one
  // dispatch, or at twilight runs of rows alternating between the day and
  // the twilight pipelines.
  void AddSkyRows(const ViewRequest& view, const Dispatch& view_dispatch, bool twilight,
                  std::vector<Dispatch>& dispatches, std::vector<bool>& barriers);
  // Whether this Sun leaves every cloud band in the Earth's shadow
  // (CloudEarthShadowElevationDeg, shaders.shadowed_clouds): the frame's
  // cloud march runs without the Sun's light march (specialization constant
  // 21), the same bytes, with the pipeline built on the first such frame.
  bool CloudsInEarthShadow(const glm::dvec3& sun) const;
  VkPipeline ShadowedCloudPipeline();
  void DestroyAll();  // every Vulkan object of the renderer; safe on a partly built one
  // Records the dispatches into one command buffer, submits, waits, and
  // records per-dispatch timings. A barrier follows every dispatch that a
  // later one reads (`barrier_after`).
  void Submit(const std::vector<Dispatch>& dispatches, const std::vector<bool>& barrier_after);
  // Points the output binding at `target` (a frame slot, or output_buffer_).
  void BindOutput(const Buffer& target);
  // The sky-view LUT when the Sun moved, the views at `offsets` (texels) of
  // `target`, the sun-disc pass; submitted and waited for.
  void SubmitViews(const Buffer& target, const glm::dvec3& sun, const std::vector<ViewRequest>& views, bool sun_disc,
                   const std::vector<size_t>& offsets, FramePart part = FramePart::kWhole);
  // Its parts: the views' sky-pass dispatches with the day pipeline (whose
  // constants the cloud pass's reuse; AddSkyRows submits them), the sun-disc
  // pass over them, the cloud pass over them.
  std::vector<Dispatch> ViewDispatches(const glm::dvec3& sun, const std::vector<ViewRequest>& views, bool sun_disc,
                                       const std::vector<size_t>& offsets) const;
  void AddSunDisc(const glm::dvec3& sun, const std::vector<ViewRequest>& views,
                  const std::vector<Dispatch>& view_dispatches, std::vector<Dispatch>& dispatches,
                  std::vector<bool>& barriers);
  void AddCloudComposites(const std::vector<Dispatch>& view_dispatches, const CloudPanorama& panorama,
                          int32_t panorama_row_range, VkPipeline cloud_pipeline, std::vector<Dispatch>& dispatches,
                          std::vector<bool>& barriers);
  std::unique_ptr<ClearSkyFrame> clear_sky_;  // RenderClearSky's frame, until CompositeClouds

  // The cloud passes' dispatches of a frame: noise (when not yet built) and
  // tables (when the sun moved) before the views; the cloud pass after them.
  void AddCloudTables(const glm::dvec3& sun, std::vector<Dispatch>& dispatches, std::vector<bool>& barriers);
  void GenerateCloudNoise();
  void CopyCloudWeatherImages();  // the weather images into the noise buffer, the volumes kept
  void FillCloudSkipMaps();       // the empty-space bounds from the noise (clouds.h), when range.w asks

  // The spectral mode's groups (quality.wavelengths > 3), else null; its
  // timings and counters are copied here after each call.
  std::unique_ptr<SpectralSky> spectral_;
  void SyncSpectral();

  static constexpr uint32_t kBindingCount = 15;  // bindings 0..14 of gpu_shared.h

  VulkanContext& context_;
  gpu::GpuAtmosphere gpu_atmosphere_{};
  QualitySettings quality_;
  EffectSettings effects_;
  AoasSwitches aoas_switches_;
  bool output_directions_ = false;
  bool style_pass_ = false;  // StylePass: style_pipeline_ is its only pipeline
  bool disc_pass_ = false;   // UsesSunDiscPass
  bool luts_ready_ = false;
  bool skyview_ready_ = false;
  glm::dvec3 skyview_sun_{0.0};  // the sun the sky-view LUT holds
  gpu::GpuClouds gpu_clouds_{};
  int cloud_layers_ = 0;  // 0: no cloud pass, no cloud pipelines
  bool cloud_noise_ready_ = false;
  bool cloud_tables_ready_ = false;
  glm::dvec3 cloud_sun_{0.0};        // the sun the cloud tables hold
  bool cloud_light_volume_ = false;  // cloud_pipeline_ reads the light volume (CloudLightVolumeOn)
  bool cloud_formation_ = false;     // the cloud pipelines read a formation's density (CloudFormationRead)
  bool cloud_cirrus_ = false;        // some layer is cirrus: streaks and the ice phase (SPEC_CLOUD_CIRRUS)
  bool CloudFormationRead(const gpu::GpuClouds& clouds) const;
  bool cloud_light_volume_ready_ = false;
  glm::dvec3 cloud_light_volume_sun_{0.0};  // the sun the light volume holds
  std::vector<float> cloud_weather_images_;

  Buffer atmosphere_buffer_;
  Buffer aoas_buffer_;
  Buffer transmittance_buffer_;
  Buffer multiscattering_buffer_;
  Buffer output_buffer_;
  Buffer skyview_buffer_;
  Buffer clouds_buffer_;       // GpuClouds
  Buffer cloud_noise_buffer_;  // noise volumes and weather maps
  // The texel views of BINDING_CLOUD_NOISE_TEXELS on (gpu_shared.h), and
  // whether each holds its whole range and the shaders read them
  // (SPEC_TEXEL_VIEWS; off, each is one texel, never read).
  VkBufferView texel_views_[TEXEL_VIEW_COUNT] = {};
  bool texel_views_whole_ = false;
  Buffer cloud_lut_buffer_;  // aerial-perspective LUT and ambient table
  Buffer dispatch_buffer_;   // a submission's SkyPush constants, one per dispatch (BINDING_DISPATCH)
  std::vector<std::unique_ptr<FrameSlot>> frame_slots_;  // RenderInPlace
  VkBuffer bound_output_ = VK_NULL_HANDLE;               // what the output binding points at

  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
  VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
  VkPipeline transmittance_pipeline_ = VK_NULL_HANDLE;
  VkPipeline multiscattering_pipeline_ = VK_NULL_HANDLE;
  VkPipeline sky_pipeline_ = VK_NULL_HANDLE;
  VkPipeline skyview_pipeline_ = VK_NULL_HANDLE;
  VkPipeline disc_pipeline_ = VK_NULL_HANDLE;
  VkPipeline cloud_lut_pipeline_ = VK_NULL_HANDLE;
  VkPipeline cloud_pipeline_ = VK_NULL_HANDLE;
  VkPipeline cloud_resample_pipeline_ = VK_NULL_HANDLE;  // views from the cloud panorama
  VkPipeline cloud_shadow_pipeline_ = VK_NULL_HANDLE;    // built on the first RenderCloudShadow
  VkPipeline twilight_sky_pipeline_ = VK_NULL_HANDLE;    // built on the first frame that marches the twilight band
  VkPipeline shadowed_cloud_pipeline_ = VK_NULL_HANDLE;  // cloud_render without the Sun's light (CloudsInEarthShadow)
  VkPipeline marched_light_cloud_pipeline_ = VK_NULL_HANDLE;  // cloud_render without the light volume
  bool shadowed_clouds_ = true;                               // ShaderSwitches::shadowed_clouds
  bool twilight_march_allowed_ = true;                        // set_twilight_march
  bool twilight_rows_ = true;                                 // ShaderSwitches::twilight_rows
  bool texel_views_allowed_ = true;                           // ShaderSwitches::texel_views
  bool formation_read_always_ = false;                        // ShaderSwitches::formation_read_always
  // TwilightRows per view shape (mapping, width, height, face).
  std::vector<std::pair<ViewRequest, std::vector<RowRange>>> twilight_row_runs_;
  VkPipeline style_pipeline_ = VK_NULL_HANDLE;  // StylePass
  bool sky_view_variant_ = false;               // sky_pipeline_ is the built-in sky-view variant
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer command_buffer_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkQueryPool query_pool_ = VK_NULL_HANDLE;
  uint32_t query_capacity_ = 0;
  bool timestamps_supported_ = false;

  std::vector<PassTiming> timings_;
  RenderCounters counters_;
};

}  // namespace skybake
