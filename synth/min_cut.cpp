#include "synth/min_cut.h"

#include <algorithm>
#include <opencv2/core.hpp>  // gcgraph.hpp needs it first
#include <opencv2/imgproc/detail/gcgraph.hpp>
#include <vector>

namespace texlume::synth {

struct MinCut::Graph {
  cv::detail::GCGraph<double> graph;
  // GCGraph refuses a graph without n-links: then each node takes its cheaper
  // label, from the costs kept here.
  std::vector<double> cost_a, cost_b;
  bool linked = false;
};

MinCut::MinCut(int nodes, int links) : graph_(std::make_unique<Graph>()) {
  graph_->graph.create(static_cast<unsigned>(nodes), 2u * static_cast<unsigned>(links));
  for (int i = 0; i < nodes; ++i) graph_->graph.addVtx();
  graph_->cost_a.assign(static_cast<std::size_t>(nodes), 0.0);
  graph_->cost_b.assign(static_cast<std::size_t>(nodes), 0.0);
}

MinCut::~MinCut() = default;

void MinCut::Link(int a, int b, double weight) {
  graph_->graph.addEdges(a, b, weight, weight);
  graph_->linked = true;
}

void MinCut::Terminals(int a, double cost_a, double cost_b) {
  // GCGraph's t-link to the source (label A) is cut when the node ends on the
  // sink side (label B), so it carries the cost of B.
  graph_->graph.addTermWeights(a, cost_b, cost_a);
  graph_->cost_a[static_cast<std::size_t>(a)] += cost_a;
  graph_->cost_b[static_cast<std::size_t>(a)] += cost_b;
}

double MinCut::Solve() {
  if (graph_->linked) return graph_->graph.maxFlow();
  double cost = 0;
  for (std::size_t i = 0; i < graph_->cost_a.size(); ++i)
    cost += std::min(graph_->cost_a[i], graph_->cost_b[i]);
  return cost;
}

bool MinCut::IsA(int a) {
  if (graph_->linked) return graph_->graph.inSourceSegment(a);
  const auto i = static_cast<std::size_t>(a);
  return graph_->cost_a[i] <= graph_->cost_b[i];
}

}  // namespace texlume::synth
