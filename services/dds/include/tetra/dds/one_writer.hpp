#pragma once
// A lockstep consumer's guard against a second Attitude writer of its unit (two services of one unit on the
// domain, or one restarted): their estimates would mix into one run unnoticed. Used by `tetra sim --dds`
// and tetra.dds.Lockstep (the player's link).

#include <dds/dds.h>

#include <string>

#include "tetra/core/result.hpp"

namespace tetra::dds {

class OneWriter {
 public:
  //! From now on a sample of a second writer is refused (before: the newest writer is followed).
  void require() { required_ = true; }
  //! Whether a sample from `writer` (dds_sample_info_t::publication_handle) may be used.
  bool accept(dds_instance_handle_t writer) {
    if (writer_ == 0 || !required_) writer_ = writer;
    second_ = second_ || writer != writer_;
    return !second_;
  }
  //! The error once a second writer was seen.
  Status status(const std::string& unit) const {
    if (!second_) return ok_status();
    return failure(
        "Attitude of unit " + unit +
        " from a second writer: two fusion services (or one restarted) serve this unit on the domain, "
        "and their estimates would mix");
  }

 private:
  dds_instance_handle_t writer_ = 0;  //!< the writer heard (0: none yet)
  bool required_ = false;
  bool second_ = false;
};

}  // namespace tetra::dds
