#include "skybake/pipeline/viewer_page.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "skybake/base/file_door.h"
#include "skybake/input/config.h"
#include "skybake/output/exr_io.h"
#include "skybake/output/exr_read.h"
#include "skybake/output/manifest.h"
#include "skybake/pipeline/pipeline.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// A file of three.js (links followed: an npm install links packages).
std::string Slurp(const fs::path& path) {
  std::string bytes;
  if (const std::string problem = ReadRegularFile(path.string(), uint64_t(64) << 20, FileLinks::kFollow, bytes);
      !problem.empty())
    throw OutputError(fmt::format("cannot read {}: it {}", path.string(), problem));
  return bytes;
}

// A file of the bake's folder through the door (file_door.h): a name a
// manifest lists, checked by the one check of listed names (manifest.h),
// opened in `dir` without following a link, a regular file (a FIFO or a
// device is refused unread) of at most kMaxShownBytes.
constexpr uint64_t kMaxShownBytes = uint64_t(1)
                                    << 30;  // a 16384 x 8192 RGBA float EXR is 2 GiB; the half scale 512 MiB

std::string FolderFile(const fs::path& dir, const std::string& name, const std::string& manifest = "") {
  if (!manifest.empty()) CheckListedName(manifest, "frames[].files[].file", name);
  std::string bytes;
  if (const std::string problem = ReadFolderFile(dir.string(), name, kMaxShownBytes, bytes); !problem.empty())
    throw OutputError(
        fmt::format("cannot read {}: it {}: bake the folder again", EscapedText((dir / name).string()), problem));
  return bytes;
}

std::string Base64(const std::string& bytes) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 2]));
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[v & 63] : '=';
  }
  return out;
}

std::string DataModule(const std::string& source) { return "data:text/javascript;base64," + Base64(source); }

// Text safe inside <script type="application/json">.
std::string ScriptSafe(std::string text) {
  size_t at = 0;
  while ((at = text.find("</", at)) != std::string::npos) text.replace(at, 2, "<\\/");
  return text;
}

fs::path ThreeDir(const ViewPageOptions& options) {
  if (!options.three_dir.empty()) return options.three_dir;
  return SKYBAKE_THREE_DEFAULT_DIR;
}

const char* kPage = R"PAGE(<!doctype html>
<!-- skybake view: the sky of a bake, in one page (skybake view DIR). Drag to look around;
     the sliders set the exposure and the frame. Needs no network and no server. -->
<html>
<head>
<meta charset="utf-8">
<title>skybake view</title>
<style>
html, body { margin: 0; height: 100%; background: #000; overflow: hidden; font: 13px sans-serif; color: #ddd; }
canvas { display: block; width: 100%; height: 100%; touch-action: none; cursor: grab; }
#panel { position: absolute; left: 8px; bottom: 8px; background: rgba(0,0,0,0.55); padding: 6px 8px; border-radius: 4px; }
#panel label { display: block; margin: 2px 0; }
</style>
<script type="importmap">@IMPORTMAP@</script>
</head>
<body>
<div id="panel">
  <label>exposure <input id="ev" type="range" min="-10" max="10" step="0.25" value="0"> <span id="evText"></span> stops</label>
  <label>frame <input id="frame" type="range" min="0" max="0" step="1" value="0"> <span id="frameText"></span></label>
  <label>tone mapping <select id="tonemap"><option value="aces">ACES filmic</option><option value="linear">linear</option></select></label>
  <span id="view"></span>
</div>
<script type="application/json" id="frames">@FRAMES@</script>
<script type="application/json" id="meta">@META@</script>
<script type="module">
import * as THREE from 'three';
import { EXRLoader } from 'three/EXRLoader';

const meta = JSON.parse(document.getElementById('meta').textContent);
const frames = JSON.parse(document.getElementById('frames').textContent);
const bytes = (b64) => Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
document.body.prepend(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(70, window.innerWidth / window.innerHeight, 0.1, 10);

// OpenEXR latlong (Imf::LatLongMap): pixel x = (0.5 - lon / 2 pi) (w - 1), y = (0.5 - lat / pi) (h - 1),
// lon = atan2(x, z), lat = asin(y); EXRLoader stores rows bottom-up, so v = 1 - (y + 0.5) / h.
const material = new THREE.ShaderMaterial({
  uniforms: { sky: { value: null }, size: { value: new THREE.Vector2(2, 1) }, gain: { value: 1 } },
  vertexShader: `varying vec3 vDirection;
    void main() { vDirection = position; gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }`,
  fragmentShader: `uniform sampler2D sky; uniform vec2 size; uniform float gain; varying vec3 vDirection;
    void main() {
      vec3 d = normalize(vDirection);
      float lon = atan(d.x, d.z), lat = asin(clamp(d.y, -1.0, 1.0));
      float x = (0.5 - lon / 6.283185307179586) * (size.x - 1.0);
      float y = (0.5 - lat / 3.141592653589793) * (size.y - 1.0);
      gl_FragColor = vec4(texture2D(sky, vec2((x + 0.5) / size.x, 1.0 - (y + 0.5) / size.y)).rgb * gain, 1.0);
      #include <tonemapping_fragment>
      #include <colorspace_fragment>
    }`,
  side: THREE.BackSide, depthWrite: false, toneMapped: true,
});
scene.add(new THREE.Mesh(new THREE.BoxGeometry(2, 2, 2), material));

const exr = new EXRLoader().setDataType(THREE.FloatType);
// A frame's texture: from the page's own base64 (f.data), or fetched from its file beside the page
// (f.url; a long sequence's later frames), once, when the frame is first shown.
function load(f) {
  if (!f.pending) f.pending = loadTexture(f);
  return f.pending;
}
async function loadTexture(f) {
  let texture;
  if (f.type === 'exr') {
    let buffer = null;
    if (f.data) buffer = bytes(f.data).buffer;
    else {
      try {
        const response = await fetch(f.url);
        if (response.ok) buffer = await response.arrayBuffer();
      } catch (e) { /* file:// pages cannot fetch */ }
    }
    if (!buffer) {
      f.missing = true;
      return null;
    }
    const data = exr.parse(buffer);
    texture = new THREE.DataTexture(data.data, data.width, data.height, data.format, data.type);
    texture.colorSpace = THREE.LinearSRGBColorSpace;
  } else {
    const image = new Image();
    const loaded = new Promise((resolve) => { image.onload = () => resolve(true); image.onerror = () => resolve(false); });
    image.src = f.data ? 'data:image/png;base64,' + f.data : f.url;
    if (!(await loaded)) {
      f.missing = true;
      return null;
    }
    texture = new THREE.Texture(image);
    texture.colorSpace = THREE.SRGBColorSpace;
    texture.flipY = true;
  }
  texture.magFilter = THREE.LinearFilter;
  texture.minFilter = THREE.LinearFilter;
  texture.generateMipmaps = false;
  texture.needsUpdate = true;
  f.texture = texture;
  return texture;
}
const textures = frames;

let yaw = 0, pitch = 0;  // degrees; yaw 0 faces North (-Z), positive turns towards East
const ev = document.getElementById('ev'), frame = document.getElementById('frame'), tonemap = document.getElementById('tonemap');
frame.max = String(frames.length - 1);
let shown = null;  // the frame on screen
function draw() {
  const f = textures[Number(frame.value)];
  if (!f.texture && !f.missing) {
    load(f).then(draw);
    if (!shown) return;
  }
  if (f.texture) shown = f;
  const g = shown;
  material.uniforms.sky.value = g.texture;
  material.uniforms.size.value.set(g.width, g.height);
  // The bake's exposure (EV100) for EXRs, in cd/m^2 once skybake:scale is undone; PNGs are already exposed.
  const base = g.type === 'exr' ? meta.exposure / g.scale : 1;
  material.uniforms.gain.value = base * Math.pow(2, Number(ev.value));
  renderer.toneMapping = tonemap.value === 'aces' ? THREE.ACESFilmicToneMapping : THREE.NoToneMapping;
  material.needsUpdate = true;
  const y = THREE.MathUtils.degToRad(yaw), p = THREE.MathUtils.degToRad(pitch);
  camera.position.set(0, 0, 0);
  camera.lookAt(Math.sin(y) * Math.cos(p), Math.sin(p), -Math.cos(y) * Math.cos(p));
  renderer.render(scene, camera);
  document.getElementById('evText').textContent = (Number(ev.value) >= 0 ? '+' : '') + ev.value;
  document.getElementById('frameText').textContent = f.missing
    ? f.label + ': ' + f.url + ' is not inside the page; serve this folder over HTTP (python3 -m http.server) to see it'
    : f.label;
  document.getElementById('view').textContent = `azimuth ${((yaw % 360) + 360) % 360}°, elevation ${pitch}°`;
}
// Dragging moves the sky with the pointer: right turns the view left, 0.25 degree per pixel.
let dragging = null;
const canvas = renderer.domElement;
canvas.addEventListener('pointerdown', (e) => { dragging = { x: e.clientX, y: e.clientY }; });
window.addEventListener('pointerup', () => { dragging = null; });
window.addEventListener('pointermove', (e) => {
  if (!dragging) return;
  yaw -= 0.25 * (e.clientX - dragging.x);
  pitch = Math.max(-89, Math.min(89, pitch + 0.25 * (e.clientY - dragging.y)));
  dragging = { x: e.clientX, y: e.clientY };
  draw();
});
for (const control of [ev, frame, tonemap]) control.addEventListener('input', draw);
window.addEventListener('resize', () => {
  renderer.setSize(window.innerWidth, window.innerHeight);
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  draw();
});
draw();

// Automation for tests: ?test=drag:DX,DY;ev:STOPS;frame:I;tonemap:linear runs the actions through the
// page's own event handlers, then POSTs the state to /report.
const test = new URLSearchParams(location.search).get('test');
if (test) {
  const set = (control, value) => { control.value = value; control.dispatchEvent(new Event('input')); };
  for (const action of test.split(';')) {
    const [name, arg] = action.split(':');
    if (name === 'drag') {
      const [dx, dy] = arg.split(',').map(Number);
      const x = 100, y = 100;
      canvas.dispatchEvent(new PointerEvent('pointerdown', { clientX: x, clientY: y, bubbles: true }));
      window.dispatchEvent(new PointerEvent('pointermove', { clientX: x + dx, clientY: y + dy, bubbles: true }));
      window.dispatchEvent(new PointerEvent('pointerup', { clientX: x + dx, clientY: y + dy, bubbles: true }));
    } else if (name === 'ev') set(ev, arg);
    else if (name === 'frame') set(frame, arg);
    else if (name === 'tonemap') set(tonemap, arg);
  }
  const f = textures[Number(frame.value)];
  await load(f);
  draw();
  await fetch('/report', { method: 'POST', body: JSON.stringify({ ok: !f.missing, yaw, pitch, frames: frames.length,
    frame: Number(frame.value), label: f.label, embedded: frames.filter((g) => g.data).length,
    shown: shown ? shown.label : null }) });
}
</script>
</body>
</html>
)PAGE";

struct Frame {
  std::string file, type, label;
  double scale = 1.0;
  std::string manifest;  // the manifest that names the file, "" for a file found in the folder
};

// What the page shows: each frame's latlong, and the bake's exposure.
struct ShownFrames {
  std::vector<Frame> frames;
  double exposure_ev100 = 0.0;
  bool metered = false;
};

// A bake's frames from its manifest.json: each frame's latlong EXR (at the
// manifest's half scale), else its preview or glTF texture PNG.
ShownFrames ManifestFrames(const fs::path& manifest_path) {
  ShownFrames shown;
  double half_scale = 1.0;
  json m = json::parse(FolderFile(manifest_path.parent_path(), manifest_path.filename().string()), nullptr, false);
  if (m.is_discarded() || !m.is_object())
    throw OutputError(fmt::format("{} is not valid JSON: bake the folder again", manifest_path.string()));
  if (m.contains("exposure_ev100") && m["exposure_ev100"].is_number()) {
    shown.exposure_ev100 = m["exposure_ev100"].get<double>();
    shown.metered = true;
  }
  if (m.contains("half_scale") && m["half_scale"].is_number()) half_scale = m["half_scale"].get<double>();
  for (const json& f : m.value("frames", json::array())) {
    Frame frame;
    for (const json& file : f.value("files", json::array())) {
      const std::string kind = file.value("kind", ""), name = file.value("file", "");
      if (kind == "latlong") frame = {name, "exr", "", half_scale};
      if ((kind == "preview" || kind == "gltf_texture") && frame.file.empty()) frame = {name, "png", "", 1.0};
    }
    if (frame.file.empty()) continue;
    frame.manifest = manifest_path.string();
    const int number = f.value("frame", 0);
    frame.label = number > 0 ? fmt::format("frame {}", number) : "the bake";
    if (f.contains("time") && f["time"].is_string()) frame.label += ", " + f["time"].get<std::string>();
    shown.frames.push_back(frame);
  }
  return shown;
}

// A folder without a manifest (skybake testpattern): its OpenEXR latlongs, in name order.
ShownFrames FolderLatlongs(const fs::path& dir) {
  std::vector<std::string> names;
  const std::regex latlong(R"(.+_latlong(\.[0-9]+)?\.exr)");
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && std::regex_match(name, latlong) && name.find("_latlong") == name.rfind("_latlong") &&
        name.find('_') == name.find("_latlong"))
      names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  ShownFrames shown;
  for (const std::string& n : names) shown.frames.push_back({n, "exr", n, 1.0, ""});
  return shown;
}

// The page's frame list: each frame's type, label, scale and size, its file
// embedded (base64) while the embedded bytes stay within embed_mib (the
// first always), else named beside the page.
json FrameEntries(const std::vector<Frame>& frames, const fs::path& dir, double embed_mib) {
  json list = json::array();
  double embedded_bytes = 0.0;
  for (const Frame& f : frames) {
    const std::string data = FolderFile(dir, f.file, f.manifest);
    embedded_bytes += double(data.size());
    const bool embed = list.empty() || embedded_bytes <= embed_mib * 1024.0 * 1024.0;
    int width = 0, height = 0;
    if (f.type == "png") {
      if (data.size() < 24) throw OutputError(fmt::format("{} is not a PNG", f.file));
      for (int i = 16; i < 20; ++i) width = (width << 8) | uint8_t(data[size_t(i)]);
      for (int i = 20; i < 24; ++i) height = (height << 8) | uint8_t(data[size_t(i)]);
    } else {
      if (const std::string problem = ExrSizeOfBytes(data, width, height); !problem.empty())
        throw OutputError(fmt::format("{} {}: bake the folder again", EscapedText((dir / f.file).string()), problem));
    }
    json entry = {{"type", f.type}, {"label", f.label}, {"scale", f.scale}, {"width", width}, {"height", height}};
    if (embed) entry["data"] = Base64(data);
    else entry["url"] = f.file;  // the manifest's names are plain file names of DIR
    list.push_back(entry);
  }
  return list;
}

// The page's import map: three.js and its EXR loader (with fflate), each
// embedded as a data: module.
json ThreeImportMap(const ViewPageOptions& options) {
  const fs::path three = ThreeDir(options);
  const fs::path core = three / "build" / "three.module.min.js";
  if (!fs::is_regular_file(core))
    throw OutputError(
        fmt::format("three.js is not at {}: run .ci/setup (npm ci in tests/viewer), or set "
                    "SKYBAKE_THREE_DIR to an npm 'three' package folder",
                    three.string()));
  std::string loader = Slurp(three / "examples" / "jsm" / "loaders" / "EXRLoader.js");
  // Its one relative import, to the import map's name.
  const std::string relative = "'../libs/fflate.module.js'";
  const size_t at = loader.find(relative);
  if (at == std::string::npos)
    throw OutputError("EXRLoader.js of " + three.string() + " does not import fflate as expected");
  loader.replace(at, relative.size(), "'three/fflate'");
  return {{"imports",
           {{"three", DataModule(Slurp(core))},
            {"three/EXRLoader", DataModule(loader)},
            {"three/fflate", DataModule(Slurp(three / "examples" / "jsm" / "libs" / "fflate.module.js"))}}}};
}

}  // namespace

std::string WriteViewPage(const ViewPageOptions& options) {
  const fs::path dir(options.dir);
  const fs::path page = dir / "view.html";
  if (!fs::is_directory(dir))
    throw OutputError(fmt::format("{} is not a folder: give a bake's --out folder", options.dir));
  if (!options.force && fs::exists(fs::symlink_status(page)))
    throw OutputExistsError(fmt::format("{} already exists: pass --force to replace it", page.string()));

  const fs::path manifest_path = dir / "manifest.json";
  const ShownFrames shown = fs::is_regular_file(manifest_path) ? ManifestFrames(manifest_path) : FolderLatlongs(dir);
  if (shown.frames.empty())
    throw OutputError(
        fmt::format("{} holds no latlong to show (no manifest.json frame with a latlong EXR or "
                    "preview, no BASE_latlong.exr): bake into it first",
                    options.dir));
  const json list = FrameEntries(shown.frames, dir, options.embed_mib);
  // Exposure of the bake's EV100 (ISO 2720 calibration K = 12.5: H = 1 / (1.2 2^EV100)), 1 unmetered.
  const double exposure = shown.metered ? 1.0 / (1.2 * std::exp2(shown.exposure_ev100)) : 1.0;
  json meta = {{"exposure", exposure}, {"exposure_ev100", shown.exposure_ev100}, {"source", options.dir}};
  const json importmap = ThreeImportMap(options);

  std::string html = kPage;
  auto put = [&](const std::string& key, const std::string& value) {
    const size_t p = html.find(key);
    html.replace(p, key.size(), value);
  };
  put("@IMPORTMAP@", ScriptSafe(importmap.dump()));
  put("@FRAMES@", ScriptSafe(list.dump()));
  put("@META@", ScriptSafe(meta.dump()));
  WriteFileAtomically(page.string(), html);
  return page.string();
}

}  // namespace skybake
