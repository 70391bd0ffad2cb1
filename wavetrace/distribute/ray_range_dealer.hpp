// Image-parallel work on demand: rank 0 deals the image's camera rays out in ranges, one to
// whichever rank asks next, so that a slower rank takes fewer.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>

#include "wavetrace/distribute/mpi_session.hpp"
#include "wavetrace/stages/generate.hpp"

namespace wavetrace {

class RayRangeDealer {
 public:
  // Every rank makes one (rank 0's starts a thread answering the others). `range_rays`: rays a
  // range, > 0.
  RayRangeDealer(const MpiSession& session, std::uint64_t total_rays, std::uint64_t range_rays);
  // Rank 0: waits until every other rank was told that no range is left.
  ~RayRangeDealer();
  RayRangeDealer(const RayRangeDealer&) = delete;
  RayRangeDealer& operator=(const RayRangeDealer&) = delete;

  // This rank's next range (count 0: none left); one caller at a time (generate's lock).
  CameraRayRange next();
  // Rank 0: returns once every other rank has had its last answer (then MPI is free for
  // the collectives that follow). A no-op elsewhere.
  void finish();

  std::uint64_t ranges_taken() const { return ranges_taken_; }
  double wait_seconds() const { return wait_seconds_; }  // this rank's time waiting for answers

 private:
  CameraRayRange draw();  // the next range of the image, from any thread of rank 0
  void serve();     // rank 0's thread: one answer a request

  const MpiSession& session_;
  std::uint64_t total_rays_, range_rays_;
  std::atomic<std::uint64_t> next_first_{0};
  std::thread server_;
  std::uint64_t ranges_taken_ = 0;
  double wait_seconds_ = 0.0;
};

}  // namespace wavetrace
