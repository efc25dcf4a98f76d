#pragma once
// Distributed headless rendering over MPI (docs/distributed.md). Built with CANDELA_MPI.
//
// Every rank loads the scene; rank 0 hands out chunks of sample indices (spp-per-frame indices per
// chunk) on request, so a slow rank simply asks less often. A rank renders each sample index of
// its chunk into a zeroed film (a "layer": for the box filter each pixel's single sample, for
// weighted filters the merged tiles of that index) and sends the layers to rank 0, which adds
// them to its film in sample-index order, buffering the ones that arrive early. A single process
// accumulates exactly so (Film::add, integrator/tiles.h), hence the image is the single-process
// image bit for bit, for any number of ranks and threads.
#include "app/headless_run.h"

namespace candela {

// True when this process was started by an MPI launcher (mpirun/mpiexec of Open MPI, or srun,
// through PMIx or PMI): the environment names a rank.
bool launched_by_mpi();

// run_headless across the ranks of MPI_COMM_WORLD: initialises and finalises MPI. Rank 0 prints
// the progress and the summary, saves the checkpoints and writes the image; the other ranks are
// quiet. Returns the process exit code as run_headless does.
int run_headless_mpi(const HeadlessOptions& opt);

}  // namespace candela
