#include "sim/cli/run_picture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "sim/cli/summary_text.h"
#include "sim/viz/picture.h"

namespace sim {

namespace {

Rgb status_colour(hal::LocalizationStatus s) {
  switch (s) {
    case hal::LocalizationStatus::kSearching: return {150, 150, 150};
    case hal::LocalizationStatus::kAmbiguous: return {240, 150, 0};
    case hal::LocalizationStatus::kLocalized: return {20, 90, 230};
    case hal::LocalizationStatus::kOutsideMap: return {150, 60, 200};
    case hal::LocalizationStatus::kFault: return {220, 0, 0};
  }
  return {0, 0, 0};
}

// Notes short enough for the PNG font (12 px a character over ~1600 px).
void add_notes(const SimSummary& s, Picture* pic) {
  char buf[320];
  if (s.first_localized_step >= 0) {
    std::snprintf(buf, sizeof(buf), "first fix at step %ld after %.1f s / %.1f m (error %.2f m); %s",
                  s.first_localized_step, s.first_localized_t, s.first_localized_travelled_m, s.first_localized_err_m,
                  availability_text(s).c_str());
  } else {
    std::snprintf(buf, sizeof(buf), "never localized in %zu steps (%.1f m driven)", s.steps, s.path_length_m);
  }
  pic->notes.push_back(buf);
  std::snprintf(buf, sizeof(buf), "integrity failures %zu (localized, error > %.1f m or > %.0f deg)",
                s.integrity_failures, kIntegrityLimitM, kIntegrityLimitDeg);
  pic->notes.push_back(buf);
  pic->notes.push_back(pl_text(s));
  if (s.kidnap_step >= 0) pic->notes.push_back(kidnap_text(s));
  std::snprintf(buf, sizeof(buf), "step time p50 %.2f ms, p99 %.2f ms; %s", s.step_ms_p50, s.step_ms_p99,
                final_error_text(s).c_str());
  pic->notes.push_back(buf);
}

// Protection level as a circle around the estimate at every n-th `localized` step (about 100
// circles at most).
void add_protection_levels(const std::vector<StepRecord>& steps, Picture* pic) {
  std::size_t with_pl = 0;
  for (const StepRecord& st : steps) {
    with_pl += st.estimate.status == hal::LocalizationStatus::kLocalized && st.estimate.protection_xy_m > 0;
  }
  const std::size_t pl_every = std::max<std::size_t>(10, (with_pl + 99) / 100);
  CircleSet pl_circles{{}, {0, 170, 190}, 1.2,
                       "protection level (1 in " + std::to_string(pl_every) + " localized)"};
  std::size_t pl_seen = 0;
  for (const StepRecord& st : steps) {
    const bool loc = st.estimate.status == hal::LocalizationStatus::kLocalized;
    if (loc && st.estimate.protection_xy_m > 0 && pl_seen++ % pl_every == 0) {
      pl_circles.circles.push_back({st.estimate.x, st.estimate.y, st.estimate.protection_xy_m});
    }
  }
  if (!pl_circles.circles.empty()) pic->circle_sets.push_back(pl_circles);
}

// The ground truth as lines, broken at a kidnapping (no line across the carry).
void add_truth_lines(const std::vector<StepRecord>& steps, Picture* pic) {
  Polyline truth{{}, {0, 160, 60}, 3.0, "ground truth"};
  std::vector<Polyline> truth_before;
  for (const StepRecord& st : steps) {
    if (st.kidnapped && !truth.points.empty()) {
      truth_before.push_back(truth);
      truth_before.back().label.clear();
      truth.points.clear();
    }
    if (st.has_truth) truth.points.push_back({st.truth.x, st.truth.y});
  }
  for (const auto& l : truth_before) pic->lines.push_back(l);
  pic->lines.push_back(truth);
}

// The estimate is drawn as a line only while localized (a global localizer's best guess jumps
// around while it searches: those steps are dots coloured by status).
void add_localized_estimate_lines(const std::vector<StepRecord>& steps, Picture* pic) {
  Polyline est{{}, {20, 90, 230}, 2.0, "estimate while localized"};
  std::vector<Polyline> est_runs;
  for (const StepRecord& st : steps) {
    if (st.estimate.status == hal::LocalizationStatus::kLocalized && !st.kidnapped) {
      est.points.push_back({st.estimate.x, st.estimate.y});
    } else if (!est.points.empty()) {
      est_runs.push_back(est);
      est.points.clear();
    }
  }
  if (!est.points.empty()) est_runs.push_back(est);
  for (size_t i = 0; i < est_runs.size(); ++i) {
    if (i > 0) est_runs[i].label.clear();
    pic->lines.push_back(est_runs[i]);
  }
}

// A dot for every pose the localizer gave (a dead-reckoning pose while `searching` too), never for
// the (0, 0, 0) placeholder of a step without one.
void add_status_dots(const std::vector<StepRecord>& steps, Picture* pic) {
  PointSet by_status[5];
  const char* names[5] = {"searching", "ambiguous", "localized", "outside-map", "fault"};
  for (int i = 0; i < 5; ++i) {
    by_status[i].color = status_colour(static_cast<hal::LocalizationStatus>(i));
    by_status[i].radius_px = 2.0;
    by_status[i].label = std::string("estimate: ") + names[i];
  }
  for (const StepRecord& st : steps) {
    const hal::PoseEstimate& e = st.estimate;
    const int k = static_cast<int>(e.status);
    if (k >= 0 && k < 5 && !is_placeholder_pose(e) && e.status != hal::LocalizationStatus::kFault) {
      by_status[k].points.push_back({e.x, e.y});
    }
  }
  for (auto& ps : by_status) {
    if (!ps.points.empty()) pic->point_sets.push_back(ps);
  }
}

// Every integrity failure as a cross; shown (with its count) whenever there is a fix, so a clean
// run says "0" in the legend.
void add_integrity_failures(const SimResult& r, Picture* pic) {
  const SimSummary& s = r.summary;
  PointSet failures{{}, {255, 0, 40}, 7.0,
                    "integrity failure (" + std::to_string(s.integrity_failures) + ")",
                    PointShape::kCross};
  for (const StepRecord& st : r.steps) {
    const bool loc = st.estimate.status == hal::LocalizationStatus::kLocalized;
    if (loc && std::isfinite(st.err_m) && (st.err_m > kIntegrityLimitM || st.err_deg > kIntegrityLimitDeg)) {
      failures.points.push_back({st.estimate.x, st.estimate.y});
    }
  }
  if (s.first_localized_step >= 0) pic->point_sets.push_back(failures);
}

void add_last_hypotheses(const SimResult& r, Picture* pic) {
  if (r.last_hypotheses.empty()) return;
  PointSet h{{}, {230, 30, 30}, 3.0, "hypotheses (step " + std::to_string(r.last_hypotheses_step) + ")"};
  for (const auto& p : r.last_hypotheses) h.points.push_back({p.x, p.y});
  pic->point_sets.push_back(h);
}

// Start and end of the truth, where the robot was carried to, and the first fix.
void add_markers(const SimResult& r, Picture* pic) {
  const SimSummary& s = r.summary;
  if (!r.steps.empty() && r.steps.front().has_truth) {
    const auto& f = r.steps.front().truth;
    pic->markers.push_back({f.x, f.y, f.theta, {0, 160, 60}, 7.0, "start"});
    const auto& l = r.steps.back().truth;
    pic->markers.push_back({l.x, l.y, l.theta, {0, 110, 40}, 5.0, "end"});
  }
  if (s.kidnap_step >= 0) {
    const auto& k = r.steps[static_cast<size_t>(s.kidnap_step)].truth;
    pic->markers.push_back({k.x, k.y, k.theta, {200, 0, 0}, 7.0, "kidnapped to"});
  }
  if (s.first_localized_step >= 0) {
    const auto& e = r.steps[static_cast<size_t>(s.first_localized_step)].estimate;
    pic->markers.push_back({e.x, e.y, e.theta, {20, 90, 230}, 9.0, "localized"});
  }
}

}  // namespace

bool write_pictures(const SimConfig& cfg, const SimResult& r, const World* world, const OccupancyGrid* grid,
                    std::string* err) {
  Picture pic;
  const SimSummary& s = r.summary;
  pic.title = "mml-sim: " + s.source + ", localizer " + s.localizer + ", seed " + std::to_string(cfg.seed);
  add_notes(s, &pic);
  pic.map = grid;
  if (world != nullptr) {
    for (const Box& b : world->unknown_areas) {
      pic.boxes.push_back({b.min.x(), b.min.y(), b.max.x(), b.max.y(), {200, 40, 160}, "unknown area (not in map)"});
    }
  }
  add_protection_levels(r.steps, &pic);
  add_truth_lines(r.steps, &pic);
  add_localized_estimate_lines(r.steps, &pic);
  add_status_dots(r.steps, &pic);
  add_integrity_failures(r, &pic);
  add_last_hypotheses(r, &pic);
  add_markers(r, &pic);
  // Without a map, frame the picture on the ground truth only (a dead-reckoning estimate from the
  // origin may be far away).
  if (grid == nullptr && world != nullptr) {
    pic.x_min = world->bounds.min.x() - 1;
    pic.y_min = world->bounds.min.y() - 1;
    pic.x_max = world->bounds.max.x() + 1;
    pic.y_max = world->bounds.max.y() + 1;
  }
  const std::string base = cfg.out_dir + "/run";
  return write_svg(pic, base + ".svg", err) && write_png(pic, base + ".png", err);
}

}  // namespace sim
