#include "Partition.hpp"

#include "SceneFiles.hpp"

#include "core/MeshConfig.hpp"
#include "core/SceneConfig.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "core/parallel/Partition.hpp"
#include "coupling/Simulation.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

namespace fs = std::filesystem;


int commandPartition(const std::string& scene, const std::vector<std::string>& sets, int ranks, std::string out) {
  mfsi::Partition part;
  std::string name;
  std::vector<mfsi::LocalMeshPart> parts;
  std::vector<std::string> kept;
  std::vector<std::vector<mfsi::lid_t>> groups;
  try {
    const fs::path file = resolveScene(scene);
    const auto cfg = mfsi::SceneConfig::load(file.string(), mfsi::sceneSchema(), sets);
    name = sceneName(cfg, file);
    if (!cfg.has("mesh")) throw mfsi::InputError(cfg.where(), "scene '" + name + "' has no fluid mesh to partition");
    const mfsi::HexMesh mesh = mfsi::buildMesh(cfg.child("mesh"));
    mfsi::PartitionOptions opt;
    opt.parts = ranks;
    groups = mfsi::cellGroupsKeptTogether(cfg, mesh, &kept);
    opt.keepTogether = groups;
    part = mfsi::partitionGraph(mfsi::cellDualGraph(mesh), opt);
    mfsi::MeshDecomposition decomposition(mesh, part.cellRank, ranks);
    for (int r = 0; r < ranks; ++r) parts.push_back(decomposition.part(r));
  } catch (const mfsi::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  std::cout << "scene '" << name << "': " << part.cellRank.size() << " cells on " << ranks << " rank(s); edge cut "
            << part.edgeCut << " faces; imbalance " << std::fixed << std::setprecision(3) << part.imbalance << "\n";
  std::cout << "rank  owned cells  ghost cells  owned nodes  ghost nodes  neighbours  messages  bytes per exchange\n";
  for (const auto& p : parts) {
    std::int64_t bytes = 0;
    int messages = 0;
    for (std::size_t k = 0; k < p.cells.neighbours.size(); ++k) {
      const auto n = p.cells.sendOffsets[k + 1] - p.cells.sendOffsets[k];
      bytes += static_cast<std::int64_t>(n) * 8;
      messages += n > 0 ? 1 : 0;
    }
    std::cout << std::setw(4) << p.rank << std::setw(13) << p.cells.nOwned << std::setw(13)
              << (p.cells.nLocal - p.cells.nOwned) << std::setw(13) << p.nodes.nOwned << std::setw(13)
              << (p.nodes.nLocal - p.nodes.nOwned) << std::setw(12) << p.cells.neighbours.size() << std::setw(10)
              << messages << std::setw(20) << bytes << "\n";
  }
  // Each membrane (and baffle) is solved or held by the rank of its cells.
  for (std::size_t g = 0; g < kept.size(); ++g)
    std::cout << "on rank " << part.cellRank[groups[g][0]] << ": " << kept[g] << " (" << groups[g].size()
              << " cells)\n";
  if (out.empty()) out = "results/" + name + "-partition" + std::to_string(ranks) + ".txt";
  const fs::path target(out), tmp = fs::path(out + ".part");
  std::error_code ec;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
  {
    std::ofstream f(tmp);
    f << "# mfsi partition: scene '" << name << "', " << part.cellRank.size() << " cells, " << ranks
      << " ranks, edge cut " << part.edgeCut << "\n# one line per cell (in the mesh's cell order): its rank\n";
    for (int r : part.cellRank) f << r << "\n";
    f.close();
    if (!f) {
      fs::remove(tmp, ec);
      std::cerr << "error: cannot write '" << tmp.string() << "'\n";
      return 4;
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    std::cerr << "error: cannot write '" << target.string() << "'\n";
    return 4;
  }
  std::cout << "wrote " << target.string() << "\n";
  return 0;
}
