// Where the photon pass leaves its photons: each thread appends to its own list, and the
// lists are merged in the order of the photons' keys, so the maps built from them (and every
// estimate) are the same for any thread count, batch size or ray order.
#pragma once

#include <cstdint>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "wavetrace/stages/photon_map.hpp"

namespace wavetrace {

class PhotonDeposits {
 public:
  // A photon's key: its emission index and the bounce depth it landed at (one landing a depth).
  static std::uint64_t key(std::uint32_t photon, std::uint32_t depth) { return std::uint64_t{photon} << 8 | depth; }

  // `caustic`: it came from a light by mirrors and glass alone (L S+ D), so it also goes into
  // the caustic map. Thread-safe.
  void add(std::uint64_t key, const Photon& photon, bool caustic);

  struct Maps {
    PhotonArray global;   // every photon that landed on a diffuse surface
    PhotonArray caustic;  // those that came by specular paths only
  };
  // Every deposit so far in key order; leaves this empty.
  Maps take();

 private:
  struct Deposit {
    std::uint64_t key;
    Photon photon;
    bool caustic;
  };
  tbb::enumerable_thread_specific<LargeArray<Deposit>> per_thread_;
};

}  // namespace wavetrace
