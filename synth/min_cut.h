#pragma once

#include <cstddef>
#include <memory>

// The one minimum cut of every engine's graph cuts (paper 004 Fig. 8; Kwatra et
// al. 2003), behind an interface of our own: nodes, n-links between them,
// t-links to the two labels, then which label each node ends with. OpenCV's
// GCGraph (Boykov-Kolmogorov, BSD/Apache licence) does the work.

namespace texlume::synth {

class MinCut {
 public:
  /// `nodes` nodes; `links` n-links expected (a hint for the allocation).
  MinCut(int nodes, int links);
  ~MinCut();
  MinCut(const MinCut&) = delete;
  MinCut& operator=(const MinCut&) = delete;

  /// An n-link of `weight` (>= 0) between nodes a and b, both ways: cut when
  /// they end with different labels.
  void Link(int a, int b, double weight);
  /// Costs of giving node a label A and label B (>= 0).
  void Terminals(int a, double cost_a, double cost_b);
  /// Solves the cut; returns its cost (the maximum flow).
  double Solve();
  /// After Solve: whether node a ends with label A.
  bool IsA(int a);

 private:
  struct Graph;
  std::unique_ptr<Graph> graph_;
};

}  // namespace texlume::synth
