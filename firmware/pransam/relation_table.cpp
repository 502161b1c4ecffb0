#include "firmware/pransam/relation_table.h"

#include "firmware/base/memory_report.h"

namespace fw::pransam {

Status RelationTable::allocate(StartupArena& arena, const char* name) {
  Result<Triple*> r = arena.allocate_array<Triple>(kNumSlots, name);
  if (!r) return r.status();
  slots_ = *r;
  read_only_ = false;
  stats_ = RelationTableStats{};
  return MemoryReport::instance().add({"pransam", name, kNumSlots * sizeof(Triple), kNumSlots, nullptr});
}

void RelationTable::clear() {
  if (read_only_ || slots_ == nullptr) return;
  for (std::size_t i = 0; i < kNumSlots; ++i) slots_[i] = Triple{};
  stats_ = RelationTableStats{};
}

void RelationTable::clear_slots(const std::uint32_t* slots, std::size_t n) {
  if (read_only_ || slots_ == nullptr) return;
  for (std::size_t i = 0; i < n; ++i) slots_[slots[i]] = Triple{};
  stats_ = RelationTableStats{};
}

std::size_t RelationTable::count_filled() const {
  if (slots_ == nullptr) return 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < kNumSlots; ++i) n += slots_[i].empty() ? 0 : 1;
  return n;
}

}  // namespace fw::pransam
