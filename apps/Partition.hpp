#pragma once
// `mfsi partition`: the decomposition of a scene's mesh over N ranks, and its figures.

#include <string>
#include <vector>

/// \brief `mfsi partition SCENE -n N [--set ...] [--out FILE]`: METIS on the scene's cell graph
/// with the cells of every membrane (its baffle's two sides or its wall patch) kept on one rank;
/// prints per rank the owned and ghost cells, the halo's messages and bytes per exchange of one
/// cell value, and the edge cut and imbalance; writes the cell -> rank map to `out` (default
/// results/<scene>-partition<N>.txt; one rank per line after '#' header lines), under a temporary
/// name renamed when complete.
/// \return 0 ok; 2 bad input; 4 the file could not be written.
int commandPartition(const std::string& scene, const std::vector<std::string>& sets, int ranks, std::string out);
