#pragma once

#include <Eigen/Core>
#include <array>
#include <utility>
#include <vector>

#include "atlas/chart_parts.h"
#include "mesh/mesh.h"
#include "synth/triangle_parts.h"

// The fans of strip charts (MakeStripCharts, step 0): the faces around a
// vertex cut into sectors that each fit a band.
namespace texlume::atlas::chart_parts {

/// The corner (0, 1, 2) of `face` at mesh vertex `vertex`, or -1.
int CornerOf(const mesh::TriangleMesh& mesh, int face, int vertex);

/// The face across edge (a, b) of `face`, or -1.
int FaceAcross(const mesh::TriangleMesh& mesh,
               const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, int face, int a,
               int b);

/// The band's 180-degree turn about its centre line: maps a strip growing
/// towards -x onto one growing towards +x, keeping the orientation. Corners
/// are on the band's lines and stay exactly on them.
Eigen::Vector2d TurnBand(const Eigen::Vector2d& q, double y_bottom, double y_top);

/// The faces `in_fan` marks around `v`, as runs in counter-clockwise order:
/// each run starts where its clockwise neighbour is not in the fan; a closed
/// ring starts at its lowest face.
std::vector<std::vector<int>> FanRuns(
    const mesh::TriangleMesh& mesh, const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    int v, const std::vector<int>& faces, const std::vector<char>& in_fan);

/// A run of faces around `v` (counter-clockwise) unfolded rigidly about `v`
/// and cut into sectors, each turned so its bisector is upright with `v` at
/// (0, y_bottom): per sector its faces' corners in band texels. When the run is
/// flat, each sector also takes the free faces beyond it in the same plane
/// (a cap subdivided into rings) whose centroids lie within its angles. The
/// number of sectors minimises the row area they need when upright and turned
/// sectors alternate, about n (R^2 tan(beta / 2) + 2 g R / cos(beta / 2)) for
/// n sectors of angle beta, radius R and gutter g, with beta at most 90
/// degrees. Empty when the run is shorter than 3 faces or wider than `max_length`.
std::vector<std::vector<std::pair<int, Corners>>> FanSectors(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, const std::vector<char>& used,
    int v, const std::vector<int>& run, double t, int gutter, double max_length, double y_bottom);

}  // namespace texlume::atlas::chart_parts
