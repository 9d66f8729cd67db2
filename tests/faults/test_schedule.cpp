// The fault schedule: strict YAML through the scenario's ExtraKeys hook, every campaign file.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "bbw/faults/schedule_yaml.hpp"
#include "bbw/faults/link_faults.hpp"
#include "closed_loop.hpp"

using namespace bbw::faults;
using bbw::config::ConfigError;

namespace {

const char* kBase = R"(name: t
seed: 1
duration_s: 2.0
plant: ../../plant/ecaliper.yaml
demand: {max_clamp_force_kN: 40, front_share: 0.6, profile: [[0, 0], [1, 0.5]]}
corners:
  - {name: FL, temperature_C: 30, drive: {mode: demand, feedback: load_cell}}
  - {name: RR, temperature_C: 30, drive: {mode: demand, feedback: load_cell}}
)";

FaultScenario parse(const std::string& faults) {
  return load_fault_scenario_string(std::string(kBase) + faults, test::source_path("config/scenarios/faults/inline.yaml"));
}

std::string key_of_error(const std::string& faults) {
  try {
    parse(faults);
  } catch (const ConfigError& e) {
    return e.key_path() + " | " + e.rule();
  }
  return "no error";
}

}  // namespace

TEST(FaultSchedule, EveryCampaignFileLoadsAndTogetherTheyCoverEveryType) {
  std::set<FaultType> types;
  std::size_t files = 0, standby_files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(test::source_path("config/scenarios/faults"))) {
    if (entry.path().extension() != ".yaml") continue;
    const auto fs = load_fault_scenario(entry.path().string());
    if (fs.faults.standby) {  // the hot-standby CCU's failover scenarios (issue 16): CCU faults only
      ++standby_files;
      EXPECT_EQ(entry.path().filename().string().rfind("ccu_failover_", 0), 0u) << entry.path();
      for (const auto& f : fs.faults.faults) {
        EXPECT_TRUE(is_ccu(f.target)) << entry.path();
        types.insert(f.type);
      }
      continue;
    }
    ++files;
    if (fs.scenario.name.rfind("fault_free_", 0) == 0) {  // fault-free by name
      EXPECT_TRUE(fs.faults.empty());
    } else if (fs.scenario.name == "load_cell_drift_then_a_resolver_offset" ||
               fs.scenario.name == "load_cell_drift_then_a_total_loss_released" ||
               fs.scenario.name == "load_cell_drift_on_a_seized_caliper_at_the_pads" ||
               fs.scenario.name == "resolver_offset_then_a_total_loss" ||
               fs.scenario.name == "resolver_offset_then_a_drive_seized_in_a_hard_stop" ||
               fs.scenario.name == "total_loss_after_a_link_silence" ||
               fs.scenario.name == "load_cell_dropout_released_onto_the_end_stop" ||
               fs.scenario.name == "torque_loss_then_a_stuck_load_cell_in_a_hold" ||
               fs.scenario.name == "resolver_stuck_then_a_load_cell_bias_in_a_hard_stop" ||
               fs.scenario.name == "load_cell_drift_after_a_stuck_resolver_in_a_hard_stop" ||
               fs.scenario.name == "torque_loss_then_a_load_cell_bias_in_a_slow_release") {  // two faults, one corner
      ASSERT_EQ(fs.faults.faults.size(), 2u) << entry.path();
      EXPECT_EQ(fs.faults.faults[0].target, fs.faults.faults[1].target);
      for (const auto& f : fs.faults.faults) types.insert(f.type);
    } else {
      ASSERT_EQ(fs.faults.faults.size(), 1u) << entry.path();
      types.insert(fs.faults.faults[0].type);
    }
  }
  EXPECT_EQ(files, 67u);  // stiff calipers in slow ramps that never fit (fault-free); lagging load cells in ABS on a soft and a stiff caliper (fault-free); stiff calipers crossing their play in holds (fault-free, and beside a resolver offset); a viscous caliper seized in a fast driver's hard stop; three drives of wide keys after a restart or a resolver finding (a link silence, a stuck resolver cleared, a resolver offset in a hold); a load-cell drift past the guard's range after its finding; soft calipers' load cells lost in hard stops beyond the calibrator's range (after a fit and before one); two fault-free drives of calipers ten times softer (back from beyond the guard's 10 rev; a hold after a delayed key reversal) and one ten times stiffer (a motor creeping inside the play); a viscous caliper's fast reversal, fault-free and with a load-cell bias, and a drift in its fast apply; a drive seized in a hard stop beside a healthy corner whose wide keys pull its load cell below 0;
                          // three fault-free drives of the extreme population with the plant's newer effects (keys holding friction
                          // at the released position, a slow reversal below the trusted range, a noisy load cell released); calipers with pad creep, load-dependent friction, a hot load cell's thermal drift: fault-free, and with a
                          // load-cell bias in a hard stop; actuator_seized three times: at a peak, in a hold, in a hot hard stop; load_cell bias four
                          // times: in a hold, while applying, before the first fit, in a hard stop released on the
                          // curve; load_cell drift four times: in a stop, followed by the loop in a hard stop,
                          // while the brake modulates, below the trusted range; load_cell dropout twice: in a
                          // stop, across a reversal; torque_loss twice: applying, in a hold; a torque loss then a load-cell bias in a slow release; a load-cell drift
                          // then a resolver offset on one corner; a load-cell drift then a total loss, released, on
                          // one corner; a load-cell drift on a caliper seized at the pads; a total loss while
                          // applying at speed; a resolver offset then a total loss, then a seizure in a hard stop,
                          // on one corner; a total loss after a link silence; a load cell's noise and a dropout,
                          // each released onto the end stop; a torque loss then a stuck load cell on one
                          // corner; a resolver stuck in a hard stop, released onto the end stop, and then
                          // a load-cell bias on its corner, or a load-cell drift on it
  EXPECT_EQ(standby_files, 4u);  // ccu_failover_{kill,hang,link_cut,both_lost}
  EXPECT_EQ(types.size(), 14u);  // every FaultType; stuck appears for both sensors
}

TEST(FaultSchedule, ReadsEachTypeWithItsParameters) {
  const auto fs = parse(R"(faults:
  - {at_s: 0.5, corner: FL, part: load_cell, type: bias, bias_kN: -1.5, duration_s: 0.2}
  - {at_s: 0.5, corner: RR, part: actuator, type: torque_loss, loss_percent: 40}
  - {at_s: 0.6, corner: RR, part: network, type: delay, delay_ms: 12}
  - {at_s: 0.7, corner: FL, part: process, type: kill, restart_after_s: 0.3}
  - {at_s: 0.8, corner: CCU, part: process, type: kill}
)");
  ASSERT_EQ(fs.faults.faults.size(), 5u);
  const auto& b = fs.faults.faults[0];
  EXPECT_EQ(b.type, FaultType::Bias);
  EXPECT_DOUBLE_EQ(b.bias_kN, -1.5);
  EXPECT_DOUBLE_EQ(b.end_s(), 0.7);
  EXPECT_TRUE(b.active_at(0.5));
  EXPECT_FALSE(b.active_at(0.7));
  EXPECT_GT(b.line, 0);
  EXPECT_DOUBLE_EQ(fs.faults.faults[1].torque_loss_percent, 40.0);
  EXPECT_DOUBLE_EQ(fs.faults.faults[2].delay_ms, 12.0);
  EXPECT_FALSE(fs.faults.faults[2].duration_s.has_value());
  EXPECT_DOUBLE_EQ(fs.faults.faults[3].end_s(), 1.0);
  EXPECT_TRUE(std::isinf(fs.faults.faults[4].end_s()));
  EXPECT_EQ(fs.faults.for_target(Target::RR).size(), 2u);
}

TEST(FaultSchedule, RejectsWhatIsWrongNamingKeyAndRule) {
  EXPECT_EQ(key_of_error("faults:\n  - {at_s: 0.5, corner: FL, part: resolver, type: bias, bias_kN: 1}\n").substr(0, 15),
            "faults[0].type ");
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: FL, part: load_cell, type: bias}\n").find("faults[0].bias_kN"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: FL, part: load_cell, type: bias, bias_kN: 0}\n").find("must not be 0"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: FL, part: load_cell, type: stuck, extra: 1}\n").find("faults[0].extra"),
            std::string::npos);
  // A CCU's only network fault is link_cut (a hot-standby run, issue 16).
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: CCU, part: network, type: silence, duration_s: 1}\n").find("faults[0].type"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: FL, part: network, type: silence}\n").find("faults[0].duration_s"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: FL, part: process, type: kill, duration_s: 1}\n").find("restart_after_s"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: FL, part: actuator, type: torque_loss, loss_percent: 100}\n").find("loss_percent"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: FR, part: load_cell, type: stuck}\n").find("no corner named FR"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 2.5, corner: FL, part: load_cell, type: stuck}\n").find("faults[0].at_s"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: -1, corner: FL, part: load_cell, type: stuck}\n").find("faults[0].at_s"),
            std::string::npos);
}

TEST(FaultSchedule, HotStandbyFaultsAndTheStandbyKey) {
  const auto fs = parse(R"(standby: true
faults:
  - {at_s: 0.5, corner: CCU, part: process, type: hang, resume_after_s: 0.25}
  - {at_s: 0.6, corner: CCU, part: network, type: link_cut, duration_s: 0.3}
  - {at_s: 0.9, corner: CCU_STANDBY, part: process, type: kill}
)");
  EXPECT_TRUE(fs.faults.standby);
  ASSERT_EQ(fs.faults.faults.size(), 3u);
  EXPECT_EQ(fs.faults.faults[0].type, FaultType::Hang);
  EXPECT_DOUBLE_EQ(fs.faults.faults[0].end_s(), 0.75);
  EXPECT_EQ(fs.faults.faults[1].type, FaultType::LinkCut);
  EXPECT_EQ(part_of(FaultType::LinkCut), Part::Network);
  EXPECT_DOUBLE_EQ(fs.faults.faults[1].end_s(), 0.9);
  EXPECT_EQ(fs.faults.faults[2].target, Target::CcuStandby);
  EXPECT_STREQ(to_string(Target::CcuStandby), "CCU_STANDBY");
  const auto acts = process_actions(fs.faults);  // a link cut is no process action
  ASSERT_EQ(acts.size(), 3u);
  EXPECT_EQ(acts[0].kind, ProcessAction::Kind::Hang);
  EXPECT_EQ(acts[1].kind, ProcessAction::Kind::Resume);
  EXPECT_DOUBLE_EQ(acts[1].at_s, 0.75);
  EXPECT_EQ(acts[2].kind, ProcessAction::Kind::Kill);
  EXPECT_EQ(acts[2].target, Target::CcuStandby);
  EXPECT_FALSE(parse("faults: []\n").faults.standby);

  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: CCU_STANDBY, part: process, type: kill}\n")
                .find("faults[0].corner | CCU_STANDBY needs a standby CCU"),
            std::string::npos);
  EXPECT_NE(key_of_error("standby: yes please\n").find("standby"), std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: FL, part: process, type: hang}\n").find("faults[0].type"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: RR, part: network, type: link_cut}\n").find("faults[0].type"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: CCU, part: process, type: hang, duration_s: 1}\n")
                .find("resume_after_s"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: CCU, part: process, type: kill, restart_after_s: 1}\n")
                .find("faults[0].restart_after_s | a CCU is not restarted"),
            std::string::npos);
  EXPECT_NE(key_of_error("faults:\n  - {at_s: 0.5, corner: CCU, part: load_cell, type: stuck}\n").find("faults[0].part"),
            std::string::npos);
}

TEST(FaultSchedule, WithoutTheHookAFaultListIsAnUnknownKey) {
  EXPECT_THROW(bbw::scenario::load_scenario(test::source_path("config/scenarios/faults/load_cell_bias.yaml")), ConfigError);
  EXPECT_NO_THROW(load_fault_scenario(test::source_path("config/scenarios/faults/load_cell_bias.yaml")));
}

TEST(FaultSchedule, LinkFaultsAnswerInTimeAndProcessActionsAreOrdered) {
  const auto fs = parse(R"(faults:
  - {at_s: 0.5, corner: RR, part: network, type: silence, duration_s: 0.2}
  - {at_s: 0.6, corner: RR, part: network, type: delay, delay_ms: 30, duration_s: 0.5}
  - {at_s: 0.9, corner: FL, part: process, type: kill, restart_after_s: 0.3}
  - {at_s: 0.2, corner: CCU, part: process, type: kill}
)");
  const LinkFaults rr(fs.faults, Target::RR);
  EXPECT_FALSE(rr.silenced(0.49));
  EXPECT_TRUE(rr.silenced(0.5));
  EXPECT_FALSE(rr.silenced(0.7));
  EXPECT_DOUBLE_EQ(rr.delay_s(0.55), 0.0);
  EXPECT_DOUBLE_EQ(rr.delay_s(0.65), 0.03);
  EXPECT_TRUE(rr.sends(0.8));
  const LinkFaults fl(fs.faults, Target::FL);
  EXPECT_TRUE(fl.killed(1.0));
  EXPECT_FALSE(fl.killed(1.2));
  const auto acts = process_actions(fs.faults);
  ASSERT_EQ(acts.size(), 3u);
  EXPECT_EQ(acts[0].target, Target::CCU);
  EXPECT_EQ(acts[1].kind, ProcessAction::Kind::Kill);
  EXPECT_EQ(acts[2].kind, ProcessAction::Kind::Restart);
  EXPECT_DOUBLE_EQ(acts[2].at_s, 1.2);
}

TEST(DelayQueue, ReleasesInOrderWhenDueAndRefusesWhenFull) {
  DelayQueue<int, 3> q;
  EXPECT_TRUE(q.push(0.03, 1));
  EXPECT_TRUE(q.push(0.01, 2));  // a shrinking delay does not overtake
  EXPECT_TRUE(q.push(0.05, 3));
  EXPECT_FALSE(q.push(0.06, 4));
  EXPECT_FALSE(q.pop_due(0.02).has_value());
  EXPECT_EQ(*q.pop_due(0.03), 1);
  EXPECT_EQ(*q.pop_due(0.03), 2);
  EXPECT_FALSE(q.pop_due(0.04).has_value());
  EXPECT_EQ(*q.pop_due(0.05), 3);
  EXPECT_EQ(q.size(), 0u);
}

// A scenario declares the processes ./bbw run starts (issue 12): ccu, ccu_standby with a standby,
// each of its corners; what it leaves out or adds is refused with the file, line, key and rule.
TEST(FaultSchedule, DeclaredProcessesAreTheScenariosCornersAndCcus) {
  const auto declared = parse("processes: [ccu, FL, RR]\n");
  EXPECT_EQ(declared.scenario.processes, (std::vector<std::string>{"ccu", "FL", "RR"}));
  EXPECT_EQ(declared.scenario.processes_line, 9);
  EXPECT_EQ(run_processes(declared.scenario.processes, {"FL", "RR"}, declared.faults),
            (std::vector<std::string>{"ccu", "FL", "RR"}));
  const auto plain = parse("");
  EXPECT_TRUE(plain.scenario.processes.empty());
  EXPECT_EQ(run_processes({}, {"FL", "RR"}, plain.faults), (std::vector<std::string>{"ccu", "FL", "RR"}));
  const auto standby = parse("standby: true\nprocesses: [ccu, ccu_standby, FL, RR]\n");
  EXPECT_EQ(run_processes({}, {"FL", "RR"}, standby.faults), (std::vector<std::string>{"ccu", "ccu_standby", "FL", "RR"}));

  EXPECT_EQ(key_of_error("processes: [ccu, FL]\n"),
            "processes | corner RR of this scenario has no process: list it (each corner runs as one)");
  EXPECT_EQ(key_of_error("processes: [ccu, FL, RR, FR]\n"), "processes | no corner named FR in this scenario");
  EXPECT_EQ(key_of_error("processes: [FL, RR]\n"), "processes | a run needs its CCU: list ccu");
  EXPECT_EQ(key_of_error("processes: [ccu, FL, RR, FL]\n"), "processes | 'FL' is listed twice");
  EXPECT_EQ(key_of_error("processes: [ccu, FL, RR, pedal]\n"),
            "processes | 'pedal' runs in a vehicle scenario only (config/scenarios/vehicle/)");
  EXPECT_EQ(key_of_error("processes: [ccu, FL, RR, gateway]\n"),
            "processes | unknown process 'gateway' (ccu, ccu_standby, FL, FR, RL, RR)");
  EXPECT_EQ(key_of_error("processes: [ccu, ccu_standby, FL, RR]\n"), "processes | ccu_standby needs standby: true (a hot-standby run)");
  EXPECT_EQ(key_of_error("standby: true\nprocesses: [ccu, FL, RR]\n"),
            "processes | standby: true runs a hot-standby CCU: list ccu_standby");
  EXPECT_NE(key_of_error("processes: ccu\n").find("processes | must be a non-empty list of strings"), std::string::npos);
  EXPECT_NE(key_of_error("processes: []\n").find("processes | must be a non-empty list of strings"), std::string::npos);
}

// Every shipped four-corner scenario declares its processes, and they are what it runs.
TEST(FaultSchedule, EveryShippedRunScenarioDeclaresItsProcesses) {
  std::vector<std::string> files{test::source_path("config/scenarios/four_corner_rig.yaml"),
                                 test::source_path("config/scenarios/vehicle_stop.yaml")};
  for (const auto& e : std::filesystem::directory_iterator(test::source_path("config/scenarios/faults"))) {
    if (e.path().extension() == ".yaml") files.push_back(e.path().string());
  }
  for (const auto& f : files) {
    const auto fs = load_fault_scenario(f);
    std::vector<std::string> corners;
    for (const auto& c : fs.scenario.corners) corners.push_back(c.name);
    EXPECT_FALSE(fs.scenario.processes.empty()) << f;
    EXPECT_EQ(run_processes(fs.scenario.processes, corners, fs.faults).size(), corners.size() + (fs.faults.standby ? 2u : 1u)) << f;
  }
}
