// The [cloud_layer.formation] table of a style (cloud_formation.h): read
// with its checks, and written into the resolved style.
#pragma once

#include <functional>
#include <string>

#include <toml++/toml.h>

#include "skybake/model/cloud_formation.h"

namespace skybake {

// Reports each problem as (node, key path, message); leaves `out` as it was
// for a key that is wrong.
using FormationError = std::function<void(const toml::node*, const std::string&, const std::string&)>;
void ReadCloudFormation(const toml::node& node, const std::string& path, CloudFormation& out,
                        const FormationError& error);

// Every key of an enabled formation (a disabled one writes nothing, so a
// style without it resolves as before the automaton existed).
toml::table CloudFormationToml(const CloudFormation& f);

}  // namespace skybake
