#include "coupling/chambers/ChamberGroup.hpp"

#include <algorithm>

namespace mfsi::coupling {

Eigen::Index ChamberGroup::column(int panel) const {
  const auto it = std::find(panels.begin(), panels.end(), panel);
  return it == panels.end() ? Eigen::Index(-1) : static_cast<Eigen::Index>(it - panels.begin());
}

bool ChamberGroup::pressuresFixed() const {
  return Eigen::FullPivLU<Eigen::MatrixXd>(incidence).rank() == incidence.rows();
}

std::vector<ChamberGroup> groupChambers(const std::vector<std::vector<std::pair<int, double>>>& walls) {
  // Flood over the walls' panels from each chamber not yet in a group.
  std::vector<ChamberGroup> groups;
  std::vector<char> grouped(walls.size(), 0);
  auto hasPanel = [](const std::vector<std::pair<int, double>>& of, int panel) {
    return std::any_of(of.begin(), of.end(), [&](const std::pair<int, double>& w) { return w.first == panel; });
  };
  for (std::size_t k = 0; k < walls.size(); ++k) {
    if (grouped[k]) continue;
    ChamberGroup g;
    std::vector<int> todo{static_cast<int>(k)};
    grouped[k] = 1;
    while (!todo.empty()) {
      const int c = todo.back();
      todo.pop_back();
      g.chambers.push_back(c);
      for (const auto& [panel, sign] : walls[static_cast<std::size_t>(c)]) {
        if (g.column(panel) < 0) g.panels.push_back(panel);
        for (std::size_t o = 0; o < walls.size(); ++o)
          if (!grouped[o] && hasPanel(walls[o], panel)) {
            grouped[o] = 1;
            todo.push_back(static_cast<int>(o));
          }
      }
    }
    std::sort(g.chambers.begin(), g.chambers.end());
    g.incidence = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(g.chambers.size()),
                                        static_cast<Eigen::Index>(g.panels.size()));
    for (std::size_t r = 0; r < g.chambers.size(); ++r)
      for (const auto& [panel, sign] : walls[static_cast<std::size_t>(g.chambers[r])])
        g.incidence(static_cast<Eigen::Index>(r), g.column(panel)) = sign;
    groups.push_back(std::move(g));
  }
  return groups;
}

Eigen::VectorXd shareOut(const ChamberGroup& g, const Eigen::VectorXd& weight, const Eigen::VectorXd& d) {
  // One chamber: its walls' signs are +1 (a membrane shared with another chamber joins them).
  if (g.chambers.size() == 1) return weight.size() == 1 ? d : Eigen::VectorXd(weight * (d[0] / weight.sum()));
  const Eigen::MatrixXd& E = g.incidence;
  const Eigen::VectorXd y = (E * weight.asDiagonal() * E.transpose()).ldlt().solve(d);
  return weight.cwiseProduct(E.transpose() * y);
}

Eigen::VectorXd agreedMultipliers(const ChamberGroup& g, const Eigen::VectorXd& C, const Eigen::VectorXd& lambda) {
  if (g.chambers.size() == 1) return Eigen::VectorXd::Constant(1, C.dot(lambda) / C.sum());
  const Eigen::MatrixXd& E = g.incidence;
  return (E * C.asDiagonal() * E.transpose()).ldlt().solve(E * C.cwiseProduct(lambda));
}

}  // namespace mfsi::coupling
