// MPI for a process that mpirun started, and nothing for one started alone: the ranks of a
// distributed render and how one of them ends them all.
#pragma once

#include <string>

namespace wavetrace {

class MpiSession {
 public:
  // Starts MPI (with threads: ranks call it from TBB's workers) when a launcher of Open MPI
  // or PMIx started this process; otherwise one rank and no MPI at all. Throws when a
  // launcher asked for several ranks and this build has no MPI.
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int ranks() const { return ranks_; }
  bool distributed() const { return ranks_ > 1; }
  const std::string& host() const { return host_; }

  // Ends every rank of the job with `exit_code` (MPI_Abort): for a rank that failed, after it
  // printed why, so that the others never wait on it. Alone, exits this process.
  [[noreturn]] void abort(int exit_code) const;

  static bool built_with_mpi();
  // The ranks a launcher (mpirun, or one of PMIx or PMI) started this process among; 0 when
  // none started it. Read from the environment: MPI itself is not started.
  static int launched_ranks();

 private:
  bool started_ = false;
  int rank_ = 0;
  int ranks_ = 1;
  std::string host_;
};

}  // namespace wavetrace
