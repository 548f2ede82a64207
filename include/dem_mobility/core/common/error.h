// Error types and checking macros of the ROS-free core.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace dem_mobility::core {

/// A user-facing input error: bad configuration, nonsense parameter, unstable time step.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A numerical failure detected while running (NaN, blow-up, watchdog).
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A run stopped from outside (SIGINT, SIGTERM, a ROS shutdown) before it began to step: during a
/// long preparation (a DEM soil's pour, lid and settling). Its text says what was reached.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
template <typename... Args>
std::string Concat(const Args&... args) {
  std::ostringstream os;
  os.precision(10);
  (os << ... << args);
  return os.str();
}
}  // namespace detail

}  // namespace dem_mobility::core

/// Checks user input; always on, also in Release builds.
#define DM_THROW_UNLESS(cond, ...)                                                  \
  do {                                                                              \
    if (!(cond)) throw ::dem_mobility::core::ConfigError(::dem_mobility::core::detail::Concat(__VA_ARGS__)); \
  } while (0)

/// Checks an internal invariant; always on.
#define DM_DEMAND(cond)                                                             \
  do {                                                                              \
    if (!(cond))                                                                    \
      throw std::logic_error(::dem_mobility::core::detail::Concat("internal error: ", #cond, \
                                                            " at ", __FILE__, ":", __LINE__)); \
  } while (0)
