// libFuzzer target: the Freiburg relations reader and the trajectory reader (sim/io/relations.*),
// and the relations metric over what they accept. Input: a u16-length-prefixed relations text,
// then a trajectory text. Oracle: accepted files survive write → read with the same entries, and
// the metric over finite inputs is finite.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "sim/io/relations.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/scratch_dir.h"

namespace {
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_relations: %s\n", what);
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::ByteReader in(data, size);
  const std::vector<std::uint8_t> rel_text = in.blob();
  const std::vector<std::uint8_t> traj_text = in.rest();
  const fuzz::ScratchDir& dir = fuzz::ScratchDir::instance();
  std::string error;
  std::vector<sim::Relation> rel;
  const bool rel_ok = sim::read_relations(dir.write("in.relations", rel_text.data(), rel_text.size()), &rel, &error);
  check(rel_ok || !error.empty(), "relations: failure without an error message");
  sim::Trajectory traj;
  const bool traj_ok = sim::read_trajectory(dir.write("in.txt", traj_text.data(), traj_text.size()), &traj, &error);
  check(traj_ok || !error.empty(), "trajectory: failure without an error message");
  if (rel_ok) {
    check(sim::write_relations(dir.path("out.relations"), rel, &error), "write_relations failed");
    std::vector<sim::Relation> back;
    check(sim::read_relations(dir.path("out.relations"), &back, &error), "relations written are refused");
    check(back.size() == rel.size(), "relations round trip changed the count");
  }
  if (traj_ok) {
    check(sim::write_trajectory(dir.path("out.txt"), traj, &error), "write_trajectory failed");
    sim::Trajectory back;
    check(sim::read_trajectory(dir.path("out.txt"), &back, &error), "trajectory written is refused");
    check(back.size() == traj.size(), "trajectory round trip changed the count");
  }
  if (rel_ok && traj_ok) {
    const sim::RelationsMetric m = sim::evaluate_relations(rel, traj);
    check(m.used + m.missing == rel.size(), "metric lost relations");
    check(m.used == 0 || (std::isfinite(m.trans_mean) && std::isfinite(m.rot_mean_deg)), "metric not finite");
  }
  return 0;
}
