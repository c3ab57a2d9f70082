#pragma once
// MPI start-up shared by the command, the tests and the benchmarks.

namespace mfsi {

// MPI_Init, and for a process started on its own (no mpiexec, srun or other launcher in its
// environment) Open MPI's singleton defaults for a process that has no peers: no helper daemon and
// no network transport probed (the start-up falls from about 0.5 s to 0.07 s, which the test
// suite pays once per test). A user's own OMPI_MCA_* settings win; other MPIs ignore these names.
void mpiInit(int* argc, char*** argv);

}  // namespace mfsi
