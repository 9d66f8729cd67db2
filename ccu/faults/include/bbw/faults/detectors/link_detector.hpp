// Link and process: no sample for deadline_s is a lost link (LinkLost); the transport's
// liveliness loss, or a new incarnation of the corner, is a lost process (ProcessLost). Both
// clear when samples arrive again (a rejoin, which breaks every other detector's continuity).
#pragma once

#include "bbw/faults/detectors/detector.hpp"
#include "bbw/faults/finding.hpp"

namespace bbw::faults {

class LinkDetector {
 public:
  // An arrival (even a corrupt sample shows the corner is there). Returns true when it ends a
  // link or process loss (a rejoin): the monitor then restarts the other detectors' continuity.
  bool on_arrival(double arrival_s, DiagnosisArbiter& a);
  void on_link_event(LinkEvent e, double time_s, DiagnosisArbiter& a);
  void tick(double now_s, const MonitorParams& p, DiagnosisArbiter& a);
  bool rejoined() const { return rejoined_; }
  bool take_rejoin();
  bool process_was_lost() const { return process_lost_since_rejoin_; }

 private:
  bool any_arrival_ = false;
  double last_arrival_s_ = 0.0;
  bool rejoined_ = false;
  bool process_lost_since_rejoin_ = false;
};

}  // namespace bbw::faults
