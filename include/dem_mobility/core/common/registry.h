// The lookup every registry of kinds shares (scenes, terrains, soil rigs): the kind a file's key
// names, or an error naming the file, the key and the known kinds.
#pragma once

#include <string>
#include <vector>

#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

/// The entry of `kinds` whose name (`name(entry)`) is the value of `key` in `y`; ConfigError
/// "file: key: unknown <what> 'value' (known: a, b)" otherwise.
template <class Kind, class Name>
const Kind& FindKind(const YamlReader& y, const std::string& key, const std::vector<Kind>& kinds, Name name,
                     const std::string& what) {
  const std::string value = y.String(key);
  std::string known;
  for (const Kind& k : kinds) {
    if (name(k) == value) return k;
    known += (known.empty() ? "" : ", ") + name(k);
  }
  y.Fail(key, "unknown " + what + " '" + value + "' (known: " + known + ")");
}

}  // namespace dem_mobility::core
