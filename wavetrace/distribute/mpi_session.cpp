// Open MPI started only under a launcher, so that a plain `wavetrace render` is exactly the
// program it was (no runtime started, no threads of MPI's).
#include "wavetrace/distribute/mpi_session.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include <unistd.h>

#include <fmt/format.h>

#if WAVETRACE_HAVE_MPI
#include <mpi.h>
#endif

namespace wavetrace {
namespace {

std::string host_name() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return "?";
  return name;
}

}  // namespace

MpiSession::MpiSession() : host_(host_name()) {
  const int launched = launched_ranks();
  if (launched == 0) return;
#if WAVETRACE_HAVE_MPI
  int provided = MPI_THREAD_SINGLE;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_MULTIPLE, &provided);
  started_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
  if (provided < MPI_THREAD_MULTIPLE && ranks_ > 1) {
    // Rank 0 answers requests on a thread of its own while TBB's workers ask on the others.
    MPI_Finalize();
    started_ = false;
    throw std::runtime_error(
        "this MPI library gives no MPI_THREAD_MULTIPLE, which a distributed render needs (Open MPI 4.1 does)");
  }
#else
  if (launched > 1) {
    throw std::runtime_error(fmt::format("started by mpirun with {} ranks, but this wavetrace was built without MPI "
                                         "(install libopenmpi-dev and configure again, or build with WAVETRACE_MPI=ON)",
                                         launched));
  }
#endif
}

MpiSession::~MpiSession() {
#if WAVETRACE_HAVE_MPI
  if (started_) MPI_Finalize();
#endif
}

void MpiSession::abort(int exit_code) const {
  std::fflush(stdout);
  std::fflush(stderr);
#if WAVETRACE_HAVE_MPI
  if (started_) MPI_Abort(MPI_COMM_WORLD, exit_code);
#endif
  std::_Exit(exit_code);
}

bool MpiSession::built_with_mpi() { return WAVETRACE_HAVE_MPI != 0; }

// From the variables launchers set: Open MPI's mpirun, PMIx, PMI (srun and others).
int MpiSession::launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_SIZE", "PMI_SIZE"}) {
    if (const char* value = std::getenv(name)) return std::max(1, std::atoi(value));
  }
  return std::getenv("PMIX_RANK") != nullptr ? 1 : 0;
}

}  // namespace wavetrace
