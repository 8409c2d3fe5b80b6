#include "skybake/gpu/pipeline_cache.h"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iterator>

#include <fmt/format.h>

#include "shaders/shader_digest.h"
#include "skybake/base/file_door.h"
#include "skybake/gpu/vulkan_context.h"

namespace skybake {
namespace {

constexpr char kMagic[8] = {'S', 'K', 'B', 'K', 'P', 'C', '0', '1'};
constexpr size_t kEnvelopeBytes = 24;
// VkPipelineCacheHeaderVersionOne: 4 x uint32 and a 16-byte UUID.
constexpr size_t kVulkanHeaderBytes = 16 + VK_UUID_SIZE;

uint64_t Fnv1a64(const uint8_t* data, size_t size) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

void PutU64(std::vector<uint8_t>& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(uint8_t(v >> (8 * i)));
}

uint64_t GetU64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(p[i]) << (8 * i);
  return v;
}

uint32_t GetU32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

std::string Hex(const uint8_t* data, size_t size) {
  std::string s;
  for (size_t i = 0; i < size; ++i) s += fmt::format("{:02x}", data[i]);
  return s;
}

// The Vulkan header of the driver's data against this device (Vulkan spec,
// "Pipeline Cache Header"; the fields are in the device's byte order, which
// is the host's here, little-endian on every platform skybake builds for).
std::string VulkanHeaderMismatch(const uint8_t* payload, size_t size, const VkPhysicalDeviceProperties& device) {
  if (size < kVulkanHeaderBytes) return fmt::format("its Vulkan header is cut short ({} bytes)", size);
  const uint32_t header_size = GetU32(payload), version = GetU32(payload + 4);
  if (header_size < kVulkanHeaderBytes || header_size > size)
    return fmt::format("its Vulkan header gives headerSize {}", header_size);
  if (version != VK_PIPELINE_CACHE_HEADER_VERSION_ONE)
    return fmt::format("its Vulkan header has headerVersion {}, not VK_PIPELINE_CACHE_HEADER_VERSION_ONE", version);
  if (GetU32(payload + 8) != device.vendorID || GetU32(payload + 12) != device.deviceID)
    return "it was written by another device (vendorID or deviceID)";
  if (std::memcmp(payload + 16, device.pipelineCacheUUID, VK_UUID_SIZE) != 0)
    return "it was written by another driver (pipelineCacheUUID)";
  return "";
}

// 256 MiB: lavapipe's data for every skybake pipeline is a few MiB.
constexpr uint64_t kMaxPipelineCacheBytes = uint64_t(256) << 20;

// Through the door (file_door.h): a regular file of the folder, not a link;
// a FIFO, device or link planted in a shared cache folder is ignored with
// what it is (`problem`), not waited on, read without end or followed.
std::vector<uint8_t> ReadFile(const std::string& path, bool& exists, std::string& problem) {
  std::string bytes;
  problem = ReadRegularFile(path, kMaxPipelineCacheBytes, FileLinks::kRefuse, bytes);
  exists = problem != "no such file";
  if (!problem.empty()) {
    if (exists) problem = "it " + problem;
    return {};
  }
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

}  // namespace

std::string PipelineCacheFileName(const VkPhysicalDeviceProperties& device, uint64_t shader_digest) {
  return fmt::format("pipelines-{}-{:016x}.bin", Hex(device.pipelineCacheUUID, VK_UUID_SIZE), shader_digest);
}

std::vector<uint8_t> EncodePipelineCacheFile(const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> out(kMagic, kMagic + sizeof(kMagic));
  PutU64(out, payload.size());
  PutU64(out, Fnv1a64(payload.data(), payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

std::vector<uint8_t> DecodePipelineCacheFile(const std::vector<uint8_t>& file, const VkPhysicalDeviceProperties& device,
                                             std::string& why) {
  why.clear();
  if (file.size() < kEnvelopeBytes || std::memcmp(file.data(), kMagic, sizeof(kMagic)) != 0) {
    why = "it is not a skybake pipeline cache (no SKBKPC01 envelope)";
    return {};
  }
  const uint64_t size = GetU64(file.data() + 8);
  if (size != file.size() - kEnvelopeBytes) {
    why = fmt::format("it is cut short or too long ({} bytes of data, the envelope says {})",
                      file.size() - kEnvelopeBytes, size);
    return {};
  }
  const uint8_t* payload = file.data() + kEnvelopeBytes;
  if (Fnv1a64(payload, size_t(size)) != GetU64(file.data() + 16)) {
    why = "its checksum does not match its data";
    return {};
  }
  why = VulkanHeaderMismatch(payload, size_t(size), device);
  if (!why.empty()) return {};
  return std::vector<uint8_t>(payload, payload + size);
}

uint64_t BuildShaderDigest() { return SKYBAKE_SHADER_DIGEST; }

PipelineCache::PipelineCache(VkDevice device, const VkPhysicalDeviceProperties& properties, const std::string& folder,
                             uint64_t shader_digest)
    : device_(device), properties_(properties) {
  if (folder.empty()) return;
  status_.enabled = true;
  status_.path = (std::filesystem::path(folder) / PipelineCacheFileName(properties, shader_digest)).string();
  bool exists = false;
  std::string problem;
  const std::vector<uint8_t> file = ReadFile(status_.path, exists, problem);
  if (exists && !problem.empty()) {
    status_.ignored_because = problem;
  } else if (exists) {
    loaded_ = DecodePipelineCacheFile(file, properties, status_.ignored_because);
    status_.loaded = status_.ignored_because.empty();
    status_.loaded_bytes = loaded_.size();
  }
  VkPipelineCacheCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  info.initialDataSize = loaded_.size();
  info.pInitialData = loaded_.empty() ? nullptr : loaded_.data();
  VK_CHECK(vkCreatePipelineCache(device_, &info, nullptr, &cache_));
}

PipelineCache::~PipelineCache() {
  if (cache_) vkDestroyPipelineCache(device_, cache_, nullptr);
}

void PipelineCache::Save() {
  if (!cache_) return;
  size_t size = 0;
  std::vector<uint8_t> data;
  if (vkGetPipelineCacheData(device_, cache_, &size, nullptr) != VK_SUCCESS) {
    status_.save_error = "vkGetPipelineCacheData failed";
    return;
  }
  data.resize(size);
  // VK_INCOMPLETE when the cache grew between the calls (another thread): saved next time.
  if (size > 0 && vkGetPipelineCacheData(device_, cache_, &size, data.data()) != VK_SUCCESS) {
    status_.save_error = "vkGetPipelineCacheData did not return the whole cache";
    return;
  }
  data.resize(size);
  if ((status_.loaded || status_.saved) && data == loaded_) return;  // nothing new
  std::string why;
  DecodePipelineCacheFile(EncodePipelineCacheFile(data), properties_, why);
  if (!why.empty()) {
    status_.save_error = "the driver's data has no valid header: " + why;
    return;
  }
  const std::filesystem::path path(status_.path);
  const std::filesystem::path temp = path.string() + fmt::format(".tmp.{}", ::getpid());
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  const std::vector<uint8_t> file = EncodePipelineCacheFile(data);
  // Created new, never through a link planted at the temporary's name.
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  FILE* out = fd >= 0 ? ::fdopen(fd, "wb") : nullptr;
  if (fd >= 0 && !out) ::close(fd);
  bool ok = out && std::fwrite(file.data(), 1, file.size(), out) == file.size() && std::fflush(out) == 0 &&
            ::fsync(::fileno(out)) == 0;
  if (out) ok = std::fclose(out) == 0 && ok;
  if (ok) std::filesystem::rename(temp, path, ec);
  if (!ok || ec) {
    status_.save_error = fmt::format("cannot write {}: {}", path.string(), ok ? ec.message() : std::strerror(errno));
    std::filesystem::remove(temp, ec);
    return;
  }
  status_.saved = true;
  status_.saved_bytes = file.size();
  loaded_ = std::move(data);
}

}  // namespace skybake
