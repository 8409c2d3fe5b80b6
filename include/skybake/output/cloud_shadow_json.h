// The cloud shadow map's record in manifest.json (cloud_shadow.h), written
// and read back (merge-manifest) to the same bytes.
#pragma once

#include <nlohmann/json.hpp>

#include "skybake/model/cloud_shadow.h"

namespace skybake {

nlohmann::json CloudShadowJson(const CloudShadowInfo& info);
// Throws std::runtime_error naming the member that is missing or mistyped.
CloudShadowInfo CloudShadowFromJson(const nlohmann::json& j);

}  // namespace skybake
