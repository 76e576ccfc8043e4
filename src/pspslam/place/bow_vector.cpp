#include "pspslam/place/bow_vector.h"

#include <algorithm>
#include <cmath>

namespace pspslam {
namespace {

double l1_norm(const BowVector& v) {
  double norm = 0.0;
  for (const BowEntry& e : v.entries) norm += std::abs(static_cast<double>(e.weight));
  return norm;
}

}  // namespace

double bow_score(const BowVector& a, const BowVector& b) {
  const double norm_a = l1_norm(a);
  const double norm_b = l1_norm(b);
  if (norm_a <= 0.0 || norm_b <= 0.0) return 0.0;
  // Words only one vector has contribute |v_i| + 0 to the L1 distance; with both vectors summing
  // to 1 that leaves 1 - sum over common words of min(v_i, w_i).
  double common = 0.0;
  auto ia = a.entries.begin();
  auto ib = b.entries.begin();
  while (ia != a.entries.end() && ib != b.entries.end()) {
    if (ia->word < ib->word) {
      ++ia;
    } else if (ib->word < ia->word) {
      ++ib;
    } else {
      common += std::min(ia->weight / norm_a, ib->weight / norm_b);
      ++ia;
      ++ib;
    }
  }
  return std::clamp(common, 0.0, 1.0);
}

}  // namespace pspslam
