#include "dem_mobility/ros/terrain_figures_board.h"

#include <map>
#include <mutex>

namespace dem_mobility {
namespace {

struct Entry {
  TerrainFiguresBoard::Answer answer;  ///< the loaded terrain; empty once it closed
  TerrainReport::Response last;        ///< its last answer, once it closed
};

// one board per process; an answer is asked under the board's lock, so a terrain that closes waits
// until a read of it is over (its Close takes the same lock) and is never asked once gone
std::mutex& BoardMutex() {
  static std::mutex m;
  return m;
}
std::map<std::string, Entry>& Board() {
  static std::map<std::string, Entry> b;
  return b;
}

}  // namespace

void TerrainFiguresBoard::Open(const std::string& name, Answer answer) {
  std::lock_guard<std::mutex> lock(BoardMutex());
  Board()[name] = Entry{std::move(answer), TerrainReport::Response()};
}

void TerrainFiguresBoard::Close(const std::string& name) {
  std::lock_guard<std::mutex> lock(BoardMutex());
  const auto it = Board().find(name);
  if (it == Board().end() || !it->second.answer) return;
  it->second.last = it->second.answer();
  it->second.answer = nullptr;
}

bool TerrainFiguresBoard::Read(const std::string& name, TerrainReport::Response* out) {
  std::lock_guard<std::mutex> lock(BoardMutex());
  const auto it = Board().find(name);
  if (it == Board().end()) return false;
  *out = it->second.answer ? it->second.answer() : it->second.last;
  return true;
}

}  // namespace dem_mobility
