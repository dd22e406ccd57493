// H-system update planner and H-parameter checks (devices/h_update_timing.hpp; seeds-digest.md
// §3.1, §10 item 6, §11 T1–T8). Every expected figure is written out by hand, in µs, with the
// arithmetic in a comment; nothing is recomputed with the library's own formulas.
#include "pbvbus/s7h/h_update_timing.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace pbvbus::devices {
namespace {

// The manual's worked example (seeds §3.1): system 1 on the MPI/DP interface, system 2 on an
// external DP master; T_WA 300 ms, T_PROG 50 ms, 170 KB of DBs in work memory.
UpdatePlanInput worked_example() {
  UpdatePlanInput in;
  in.systems.push_back({"system 1", 25'000, 100'000, 30'000, 1'250'000});
  in.systems.push_back({"system 2", 30'000, 80'000, 50'000, 1'200'000});
  in.t_wa = 300'000;
  in.t_prog = 50'000;
  in.db_kb = 170;
  return in;
}

HParameters set(Us ext, Us comm, Us tp15, Us tph) {
  HParameters p;
  p.max_cycle_extension = ext;
  p.max_comm_delay = comm;
  p.t_p15 = tp15;
  p.t_ph = tph;
  return p;
}

// ---- T1 ---------------------------------------------------------------------------------------

TEST(HUpdateTiming, T1_TphCentralDpMixed) {
  // central I/O only → 30 ms (T_TRmax is ignored)
  EXPECT_EQ(t_ph(0, false), 30'000);
  EXPECT_EQ(t_ph(30'000, false), 30'000);
  // T_TRmax 30 ms → MAX(30, 3·30 = 90) = 90 ms
  EXPECT_EQ(t_ph(30'000, true), 90'000);
  // T_TRmax 8 ms with central I/O → MAX(30, 3·8 = 24) = 30 ms
  EXPECT_EQ(t_ph(8'000, true), 30'000);
  // boundary: T_TRmax 10 ms → 3·10 = 30 = 30 ms; 10.001 ms → 30.003 ms
  EXPECT_EQ(t_ph(10'000, true), 30'000);
  EXPECT_EQ(t_ph(10'001, true), 30'003);
}

// ---- T2, T3: the worked example --------------------------------------------------------------

TEST(HUpdateTiming, T2_WorkedExampleEveryTerm) {
  const UpdatePlan p = plan_update(worked_example());
  ASSERT_TRUE(p.ok()) << (p.messages.empty() ? "" : p.messages.front());
  ASSERT_EQ(p.systems.size(), 2u);
  // [1] system 1: 2·25 = 50; 50 + 300 + 50 + 100 + 30 = 530; 1250 − 530 = 720 ms
  EXPECT_EQ(p.systems[0].two_t_tr, 50'000);
  EXPECT_EQ(p.systems[0].subtracted, 530'000);
  EXPECT_EQ(p.systems[0].t_p15, 720'000);
  // [1] system 2: 2·30 = 60; 60 + 300 + 50 + 80 + 50 = 540; 1200 − 540 = 660 ms
  EXPECT_EQ(p.systems[1].two_t_tr, 60'000);
  EXPECT_EQ(p.systems[1].subtracted, 540'000);
  EXPECT_EQ(p.systems[1].t_p15, 660'000);
  // T_P15_HW = min(720, 660) = 660 ms, from system 2
  ASSERT_TRUE(p.t_p15_hw.has_value());
  EXPECT_EQ(*p.t_p15_hw, 660'000);
  EXPECT_EQ(p.hw_system, 1u);
  EXPECT_TRUE(p.has_dp);
  // T_TRmax = 30 ms; T_PH = MAX(30, 90) = 90 ms; T_P15_OD = 50 + 90 = 140 ms
  EXPECT_EQ(p.t_tr_max, 30'000);
  EXPECT_EQ(p.t_ph, 90'000);
  EXPECT_EQ(p.t_p15_od, 140'000);
  // T_P15_AWP = 75 ms + 170 · 0.7 ms = 75 000 + 119 000 = 194 000 µs
  EXPECT_EQ(p.t_p15_awp, 194'000);
  EXPECT_FALSE(p.od_exceeds_hw);
  EXPECT_FALSE(p.awp_exceeds_hw);
  EXPECT_TRUE(p.negative_systems.empty());
  EXPECT_EQ(p.abort, P15Abort::None);
  EXPECT_TRUE(p.messages.empty());
  // [3] T_P15 = MAX(194, 140) = 194 ms
  ASSERT_TRUE(p.t_p15.has_value());
  EXPECT_EQ(*p.t_p15, 194'000);
  // T3: recommended communication delay 4·194 = 776 ms, cycle extension 10·194 = 1940 ms
  EXPECT_EQ(p.recommended_comm_delay, 776'000);
  EXPECT_EQ(p.recommended_cycle_extension, 1'940'000);
  // 194 ms is a whole ms and ≥ 100 ms: settable as it is, no note
  EXPECT_EQ(p.settable_t_p15, 194'000);
  EXPECT_TRUE(p.notes.empty());
  // ticks: 194 ms · 3 636 000 ticks/ms = 705 384 000 ticks
  EXPECT_EQ(to_ticks(*p.t_p15), 705'384'000);
  EXPECT_EQ(format_ms(*p.t_p15), "194 ms");
}

TEST(HUpdateTiming, T3_RecommendedSetPassesAllChecks) {
  const UpdatePlan plan = plan_update(worked_example());
  // 1940 > 776 > 194 > 90; 50 + 90 = 140 ≤ 194; 194 ≥ 194 planned; 194 ≤ 660 = T_P15_HW;
  // 90 ≥ 90 planned T_PH; 776 and 1940 are exactly the recommendations.
  const HCheckResult r = check_h_parameters(set(1'940'000, 776'000, 194'000, 90'000), &plan);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.all_configured);
  EXPECT_TRUE(r.violations.empty()) << r.violations.front().message;
}

// ---- §10 item 6, T5: T_P15_AWP by the formula ------------------------------------------------

TEST(HUpdateTiming, T5_AwpFormulaNotTable) {
  // 75 ms + 0.7 ms · KB = 75 000 + 700 · KB µs, exact.
  EXPECT_EQ(t_p15_awp(0), 75'000);
  EXPECT_EQ(t_p15_awp(170), 194'000);  // 75 000 + 119 000
  // The table says 430 ms and 800 ms; the planner uses the formula (§10 item 6):
  EXPECT_EQ(t_p15_awp(500), 425'000);   // 75 000 + 350 000
  EXPECT_EQ(t_p15_awp(1024), 791'800);  // 75 000 + 716 800
  // T5:
  EXPECT_EQ(t_p15_awp(2048), 1'508'600);   // 75 000 + 1 433 600 (table 1.51 s)
  EXPECT_EQ(t_p15_awp(5120), 3'659'000);   // 75 000 + 3 584 000 (table 3.66 s)
  EXPECT_EQ(t_p15_awp(10240), 7'243'000);  // 75 000 + 7 168 000 (table 7.24 s)
  EXPECT_EQ(format_ms(t_p15_awp(2048)), "1508.6 ms");
  EXPECT_EQ(format_ms(t_p15_awp(1024)), "791.8 ms");
  // a negative KB count counts as 0
  EXPECT_EQ(t_p15_awp(-5), 75'000);
  // bytes → KB rounds up: 1 byte is 1 KB, 1024 bytes 1 KB, 1025 bytes 2 KB
  EXPECT_EQ(kb_from_bytes(0), 0);
  EXPECT_EQ(kb_from_bytes(1), 1);
  EXPECT_EQ(kb_from_bytes(1024), 1);
  EXPECT_EQ(kb_from_bytes(1025), 2);
  // the update time is the same formula on the changed DBs
  EXPECT_EQ(update_time(0), 75'000);
  EXPECT_EQ(update_time(170), 194'000);
}

// ---- T4: every abort case ---------------------------------------------------------------------

TEST(HUpdateTiming, T4_AbortNegativeSystemTerm) {
  UpdatePlanInput in = worked_example();
  in.systems[0].t_pto = 500'000;  // [1] 500 − 530 = −30 ms
  const UpdatePlan p = plan_update(in);
  EXPECT_FALSE(p.ok());
  EXPECT_EQ(p.abort, P15Abort::NegativeSystemTerm);
  ASSERT_EQ(p.negative_systems.size(), 1u);
  EXPECT_EQ(p.negative_systems[0], 0u);
  EXPECT_EQ(p.systems[0].t_p15, -30'000);
  EXPECT_TRUE(p.systems[0].negative());
  EXPECT_EQ(p.systems[1].t_p15, 660'000);
  // every term is still there for a printout: HW = min(−30, 660) = −30 ms
  EXPECT_EQ(p.t_p15_hw, -30'000);
  EXPECT_EQ(p.hw_system, 0u);
  EXPECT_EQ(p.t_ph, 90'000);
  EXPECT_EQ(p.t_p15_od, 140'000);
  EXPECT_EQ(p.t_p15_awp, 194'000);
  // no recommendation
  EXPECT_FALSE(p.t_p15.has_value());
  EXPECT_FALSE(p.recommended_comm_delay.has_value());
  EXPECT_FALSE(p.recommended_cycle_extension.has_value());
  EXPECT_FALSE(p.settable_t_p15.has_value());
  // [1], then both [2] comparisons also fail (140 > −30, 194 > −30): three messages, in order
  ASSERT_EQ(p.messages.size(), 3u);
  EXPECT_NE(p.messages[0].find("[1] DP master system 'system 1'"), std::string::npos);
  EXPECT_NE(p.messages[0].find("= -30 ms < 0"), std::string::npos);
  EXPECT_NE(p.messages[1].find("T_P15_OD"), std::string::npos);
  EXPECT_NE(p.messages[2].find("T_P15_AWP"), std::string::npos);
}

TEST(HUpdateTiming, T4_ZeroSystemTermIsNotNegative) {
  UpdatePlanInput in = worked_example();
  in.systems[1].t_pto = 540'000;  // [1] 540 − 540 = 0: not < 0
  const UpdatePlan p = plan_update(in);
  EXPECT_TRUE(p.negative_systems.empty());
  EXPECT_EQ(p.t_p15_hw, 0);
  // but T_P15_OD 140 > 0 → the next abort case
  EXPECT_EQ(p.abort, P15Abort::OutputCopyExceedsHw);
}

TEST(HUpdateTiming, T4_AbortOutputCopyExceedsHw) {
  UpdatePlanInput in;
  // one system: T_TR 60 → 2·60 = 120; 120 + 300 + 50 + 100 + 30 = 600; 800 − 600 = 200 ms
  in.systems.push_back({"long TTR", 60'000, 100'000, 30'000, 800'000});
  in.t_wa = 300'000;
  in.t_prog = 50'000;
  in.db_kb = 100;  // AWP = 75 + 70 = 145 ms ≤ 200
  const UpdatePlan p = plan_update(in);
  EXPECT_EQ(p.t_p15_hw, 200'000);
  EXPECT_EQ(p.t_ph, 180'000);      // MAX(30, 3·60 = 180)
  EXPECT_EQ(p.t_p15_od, 230'000);  // 50 + 180 > 200
  EXPECT_EQ(p.t_p15_awp, 145'000);
  EXPECT_TRUE(p.od_exceeds_hw);
  EXPECT_FALSE(p.awp_exceeds_hw);
  EXPECT_EQ(p.abort, P15Abort::OutputCopyExceedsHw);
  EXPECT_FALSE(p.t_p15.has_value());
  ASSERT_EQ(p.messages.size(), 1u);
  EXPECT_EQ(p.messages[0], "[2] T_P15_OD = 50 ms + T_PH = 230 ms exceeds T_P15_HW = 200 ms");
}

TEST(HUpdateTiming, T4_AbortWorkMemoryExceedsHw) {
  UpdatePlanInput in = worked_example();
  in.db_kb = 1024;  // AWP = 791.8 ms > 660 ms; OD 140 ≤ 660
  const UpdatePlan p = plan_update(in);
  EXPECT_FALSE(p.od_exceeds_hw);
  EXPECT_TRUE(p.awp_exceeds_hw);
  EXPECT_EQ(p.abort, P15Abort::WorkMemoryExceedsHw);
  EXPECT_FALSE(p.t_p15.has_value());
  ASSERT_EQ(p.messages.size(), 1u);
  EXPECT_EQ(p.messages[0],
            "[2] T_P15_AWP = 75 ms + 0.7 ms * 1024 KB = 791.8 ms exceeds T_P15_HW = 660 ms");
}

TEST(HUpdateTiming, T4_BoundariesEqualToHwDoNotAbort) {
  {
    // system 2 with T_PTO 680: 680 − 540 = 140 = T_P15_OD → allowed; 0 KB → AWP 75
    UpdatePlanInput in = worked_example();
    in.systems[1].t_pto = 680'000;
    in.db_kb = 0;
    const UpdatePlan p = plan_update(in);
    EXPECT_EQ(p.t_p15_hw, 140'000);
    EXPECT_TRUE(p.ok());
    EXPECT_EQ(p.t_p15, 140'000);  // MAX(75, 140)
  }
  {
    // T_TR 10: 20 + 300 + 50 + 100 + 30 = 500; T_PTO 645 → HW 145 = AWP(100 KB) = 75 + 70
    UpdatePlanInput in;
    in.systems.push_back({"", 10'000, 100'000, 30'000, 645'000});
    in.t_wa = 300'000;
    in.t_prog = 50'000;
    in.db_kb = 100;
    UpdatePlan p = plan_update(in);
    EXPECT_TRUE(p.ok());
    EXPECT_EQ(p.t_ph, 30'000);  // MAX(30, 30)
    EXPECT_EQ(p.t_p15_od, 80'000);
    EXPECT_EQ(p.t_p15, 145'000);  // MAX(145, 80)
    // one µs less of T_PTO → HW 144.999 < 145 → abort
    in.systems[0].t_pto = 644'999;
    p = plan_update(in);
    EXPECT_EQ(p.abort, P15Abort::WorkMemoryExceedsHw);
    EXPECT_NE(p.messages[0].find("T_P15_HW = 144.999 ms"), std::string::npos);
  }
}

TEST(HUpdateTiming, T4_InvalidInputIsReportedNotThrown) {
  UpdatePlanInput in = worked_example();
  in.t_wa = -1'000;
  in.systems[1].t_slave_um = -5;
  in.db_kb = -1;
  const UpdatePlan p = plan_update(in);
  EXPECT_EQ(p.abort, P15Abort::InvalidInput);
  EXPECT_FALSE(p.t_p15.has_value());
  ASSERT_EQ(p.messages.size(), 3u);
  EXPECT_EQ(p.messages[0], "invalid input: T_WA is negative (-1 ms)");
  EXPECT_EQ(p.messages[1], "invalid input: the DB size in work memory is out of range (-1 KB)");
  EXPECT_EQ(p.messages[2],
            "invalid input: DP master system 'system 2': T_SLAVE_UM is negative (-0.005 ms)");
  // a set checked against an invalid plan: no comparison
  const HCheckResult r = check_h_parameters(set(1'940'000, 776'000, 194'000, 90'000), &p);
  EXPECT_TRUE(r.has(HCheck::PlanAborted));
  EXPECT_FALSE(r.ok());
}

TEST(HUpdateTiming, CentralOnlyNoHwBound) {
  UpdatePlanInput in;  // no DP master system, 0 KB
  const UpdatePlan p = plan_update(in);
  EXPECT_TRUE(p.ok());
  EXPECT_FALSE(p.has_dp);
  EXPECT_FALSE(p.t_p15_hw.has_value());
  EXPECT_EQ(p.t_ph, 30'000);
  EXPECT_EQ(p.t_p15_od, 80'000);                      // 50 + 30
  EXPECT_EQ(p.t_p15_awp, 75'000);                     // 75 + 0
  EXPECT_EQ(p.t_p15, 80'000);                         // MAX(75, 80)
  EXPECT_EQ(p.recommended_comm_delay, 320'000);       // 4·80
  EXPECT_EQ(p.recommended_cycle_extension, 800'000);  // 10·80
  // 80 ms is below the settable minimum: 100 ms
  EXPECT_EQ(p.settable_t_p15, 100'000);
  ASSERT_EQ(p.notes.size(), 2u);
  EXPECT_EQ(p.notes[0],
            "T_P15 = 80 ms is not settable; the smallest settable value above it is 100 ms");
}

TEST(HUpdateTiming, SettableValueRoundsUpToWholeMs) {
  UpdatePlanInput in = worked_example();
  in.db_kb = 171;  // 75 000 + 119 700 = 194 700 µs → settable 195 ms
  const UpdatePlan p = plan_update(in);
  EXPECT_EQ(p.t_p15, 194'700);
  EXPECT_EQ(p.settable_t_p15, 195'000);
  EXPECT_EQ(p.recommended_comm_delay, 778'800);         // 4·194.7
  EXPECT_EQ(p.recommended_cycle_extension, 1'947'000);  // 10·194.7
  // no DP: 85 666 KB → 75 000 + 59 966 200 = 60 041 200 µs > 60 000 ms: not settable
  UpdatePlanInput big;
  big.db_kb = 85'666;
  const UpdatePlan q = plan_update(big);
  EXPECT_EQ(q.t_p15, 60'041'200);
  EXPECT_FALSE(q.settable_t_p15.has_value());
  EXPECT_EQ(q.notes[0], "T_P15 = 60041.2 ms exceeds the largest settable value 60000 ms");
}

TEST(HUpdateTiming, SettableAboveHwGetsANote) {
  // one system, T_TR 10: subtracted 500; T_PTO 590 → HW 90; 0 KB → AWP 75, OD 80 → T_P15 80,
  // settable 100 > HW 90
  UpdatePlanInput in;
  in.systems.push_back({"s", 10'000, 100'000, 30'000, 590'000});
  in.t_wa = 300'000;
  in.t_prog = 50'000;
  const UpdatePlan p = plan_update(in);
  EXPECT_TRUE(p.ok());
  EXPECT_EQ(p.t_p15, 80'000);
  EXPECT_EQ(p.settable_t_p15, 100'000);
  ASSERT_EQ(p.notes.size(), 2u);
  EXPECT_EQ(p.notes[1], "the smallest settable T_P15 100 ms lies above T_P15_HW = 90 ms");
}

// ---- T3: checks of a configured set ----------------------------------------------------------

TEST(HUpdateTiming, T3_OrderingViolations) {
  // extension = communication delay (776 = 776): must be strictly greater
  HCheckResult r = check_h_parameters(set(776'000, 776'000, 194'000, 90'000));
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.has(HCheck::ExtensionNotAboveCommDelay));
  EXPECT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].message,
            "max scan-cycle extension 776 ms must be greater than max communication delay 776 ms");
  // communication delay = T_P15
  r = check_h_parameters(set(1'940'000, 194'000, 194'000, 90'000));
  EXPECT_TRUE(r.has(HCheck::CommDelayNotAboveTp15));
  EXPECT_EQ(r.violations.size(), 1u);
  // T_P15 = T_PH (194 = 194): also 50 + 194 = 244 > 194
  r = check_h_parameters(set(1'940'000, 776'000, 194'000, 194'000));
  EXPECT_TRUE(r.has(HCheck::Tp15NotAboveTph));
  EXPECT_TRUE(r.has(HCheck::OutputCopyMargin));
  EXPECT_EQ(r.violations.size(), 2u);
}

TEST(HUpdateTiming, T3_OutputCopyMargin) {
  // T_PH 150: 194 > 150 holds, but 50 + 150 = 200 > 194
  HCheckResult r = check_h_parameters(set(1'940'000, 776'000, 194'000, 150'000));
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].check, HCheck::OutputCopyMargin);
  EXPECT_EQ(r.violations[0].message, "50 ms + T_PH = 200 ms must not exceed T_P15 194 ms");
  // T_PH 144: 50 + 144 = 194 ≤ 194 → allowed
  r = check_h_parameters(set(1'940'000, 776'000, 194'000, 144'000));
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.violations.empty());
}

TEST(HUpdateTiming, T3_AllFourOrNone) {
  HParameters p;  // none
  HCheckResult r = check_h_parameters(p);
  EXPECT_TRUE(r.ok());
  EXPECT_FALSE(r.all_configured);
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].check, HCheck::NoneConfigured);
  EXPECT_EQ(r.violations[0].severity, Severity::Warning);
  // all four zero = none
  r = check_h_parameters(set(0, 0, 0, 0));
  EXPECT_TRUE(r.ok());
  EXPECT_FALSE(r.all_configured);
  EXPECT_TRUE(r.has(HCheck::NoneConfigured));
  // three of four
  p = set(1'940'000, 776'000, 194'000, 90'000);
  p.t_ph.reset();
  r = check_h_parameters(p);
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].message, "configure all four H parameters or none; missing: T_PH");
  // only T_P15, out of range as well: both reported
  HParameters q;
  q.t_p15 = 99'000;
  r = check_h_parameters(q);
  EXPECT_TRUE(r.has(HCheck::Tp15OutOfRange));
  EXPECT_TRUE(r.has(HCheck::PartiallyConfigured));
}

TEST(HUpdateTiming, T3_NegativeValues) {
  const HCheckResult r = check_h_parameters(set(1'940'000, 776'000, 194'000, -1'000));
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.violations.size(), 1u);  // no ordering noise on top
  EXPECT_EQ(r.violations[0].message, "T_PH is negative (-1 ms)");
}

TEST(HUpdateTiming, T3_AgainstThePlan) {
  const UpdatePlan plan = plan_update(worked_example());  // T_P15 194, HW 660, T_PH 90
  // T_P15 150 < 194 planned
  HCheckResult r = check_h_parameters(set(1'940'000, 776'000, 150'000, 90'000), &plan);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.has(HCheck::Tp15BelowPlan));
  EXPECT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].message,
            "T_P15 150 ms is below the planned T_P15 194 ms: the update does not fit");
  // T_P15 700 > T_P15_HW 660 (776 > 700 > 90 and 140 ≤ 700 hold)
  r = check_h_parameters(set(7'000'000, 2'800'000, 700'000, 90'000), &plan);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.has(HCheck::Tp15AboveHw));
  EXPECT_EQ(r.violations.size(), 1u);
  // T_P15 660 = HW: allowed
  r = check_h_parameters(set(6'600'000, 2'640'000, 660'000, 90'000), &plan);
  EXPECT_TRUE(r.ok());
  // T_PH 60 < 90 planned
  r = check_h_parameters(set(1'940'000, 776'000, 194'000, 60'000), &plan);
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].check, HCheck::TphBelowPlan);
  // T_PH 0 with the others set: all four configured, the planned T_PH is not met
  r = check_h_parameters(set(1'940'000, 776'000, 194'000, 0), &plan);
  EXPECT_TRUE(r.all_configured);
  EXPECT_TRUE(r.has(HCheck::TphBelowPlan));
  // below the recommendations: warnings only (775 < 776, 1939 < 1940)
  r = check_h_parameters(set(1'939'000, 775'000, 194'000, 90'000), &plan);
  EXPECT_TRUE(r.ok());
  ASSERT_EQ(r.violations.size(), 2u);
  EXPECT_EQ(r.violations[0].check, HCheck::CommDelayBelowRecommended);
  EXPECT_EQ(r.violations[0].severity, Severity::Warning);
  EXPECT_EQ(r.violations[1].check, HCheck::ExtensionBelowRecommended);
  EXPECT_EQ(r.violations[1].message,
            "max scan-cycle extension 1939 ms is below the recommended 10*T_P15 = 1940 ms");
}

TEST(HUpdateTiming, T3_AgainstAnAbortedPlan) {
  UpdatePlanInput in = worked_example();
  in.db_kb = 1024;  // AWP 791.8 > 660
  const UpdatePlan plan = plan_update(in);
  HCheckResult r = check_h_parameters(set(1'940'000, 776'000, 194'000, 90'000), &plan);
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].check, HCheck::PlanAborted);
  EXPECT_NE(r.violations[0].message.find("[2] T_P15_AWP > T_P15_HW"), std::string::npos);
  // T_PH is still compared (it does not depend on the abort)
  r = check_h_parameters(set(1'940'000, 776'000, 194'000, 60'000), &plan);
  EXPECT_TRUE(r.has(HCheck::TphBelowPlan));
  EXPECT_TRUE(r.has(HCheck::PlanAborted));
}

// ---- T6: the settable range and the cam -------------------------------------------------------

TEST(HUpdateTiming, T6_SettableRangeEdges) {
  EXPECT_TRUE(t_p15_settable(0));
  EXPECT_FALSE(t_p15_settable(1'000));
  EXPECT_FALSE(t_p15_settable(99'000));
  EXPECT_FALSE(t_p15_settable(99'999));
  EXPECT_TRUE(t_p15_settable(100'000));
  EXPECT_TRUE(t_p15_settable(60'000'000));
  EXPECT_FALSE(t_p15_settable(60'000'001));
  EXPECT_FALSE(t_p15_settable(60'001'000));

  // T_P15 = 100 ms: 1000 > 400 > 100 > 50, 50 + 50 = 100 ≤ 100 → accepted
  HCheckResult r = check_h_parameters(set(1'000'000, 400'000, 100'000, 50'000));
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.violations.empty());
  // T_P15 = 99 ms with a consistent rest (990 > 396 > 99 > 49, 99 ≤ 99): range only
  r = check_h_parameters(set(990'000, 396'000, 99'000, 49'000));
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].check, HCheck::Tp15OutOfRange);
  EXPECT_EQ(r.violations[0].message, "T_P15 = 99 ms is not settable: 0 or 100..60000 ms only");
  // T_P15 = 60000 ms: 600000 > 240000 > 60000 > 90 → accepted
  r = check_h_parameters(set(600'000'000, 240'000'000, 60'000'000, 90'000));
  EXPECT_TRUE(r.violations.empty());
  // T_P15 = 60001 ms: range only
  r = check_h_parameters(set(600'010'000, 240'004'000, 60'001'000, 90'000));
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].check, HCheck::Tp15OutOfRange);
  // T_P15 = 0 is in range: with all four 0 it means "none configured"
  r = check_h_parameters(set(0, 0, 0, 0));
  EXPECT_FALSE(r.has(HCheck::Tp15OutOfRange));
  EXPECT_TRUE(r.ok());
  // T_P15 = 0 with the others set: not a range error, but 0 > T_PH 0 and 50 + 0 ≤ 0 fail
  r = check_h_parameters(set(1'940'000, 776'000, 0, 0));
  EXPECT_FALSE(r.has(HCheck::Tp15OutOfRange));
  EXPECT_TRUE(r.has(HCheck::Tp15NotAboveTph));
  EXPECT_TRUE(r.has(HCheck::OutputCopyMargin));
  EXPECT_EQ(r.violations.size(), 2u);
  // STEP 7 sets whole ms: 194.5 ms is refused
  r = check_h_parameters(set(1'940'000, 776'000, 194'500, 90'000));
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].check, HCheck::Tp15NotWholeMs);
  EXPECT_EQ(r.violations[0].message, "T_P15 = 194.5 ms is not a whole number of milliseconds");
}

TEST(HUpdateTiming, T6_CamPulseBelowAnySettableT_P15) {
  // 10 km/h = 10 000 000 mm / 3 600 000 ms = 2.78 mm/ms; 50 mm → 3600 · 50 / 10 = 18 000 µs
  const Us cam = cam_pulse_duration(50, 10);
  EXPECT_EQ(cam, 18'000);
  EXPECT_LT(cam, kTp15SettableMin);  // 18 ms < 100 ms, the smallest non-zero T_P15
  EXPECT_FALSE(t_p15_settable(cam));
  // rounding down: 1 mm at 7 km/h = 3600/7 = 514.28… → 514 µs
  EXPECT_EQ(cam_pulse_duration(1, 7), 514);
  EXPECT_EQ(cam_pulse_duration(50, 0), 0);
}

// ---- T7: minimum input-signal duration ---------------------------------------------------------

TEST(HUpdateTiming, T7_MinimumSignalDuration) {
  // t_IO 10 ms, OB 35 every 100 ms running 5 ms, 50 KB of changed DBs, higher classes 3 ms:
  // 2·10 = 20; update 75 + 0.7·50 = 75 + 35 = 110; 20 + 100 + 5 + 110 + 3 = 238 ms
  const SignalDuration d = min_signal_duration({10'000, 100'000, 5'000, 50, 3'000});
  EXPECT_EQ(d.two_t_io, 20'000);
  EXPECT_EQ(d.t_call, 100'000);
  EXPECT_EQ(d.t_run, 5'000);
  EXPECT_EQ(d.update_time, 110'000);
  EXPECT_EQ(d.t_higher, 3'000);
  EXPECT_EQ(d.total, 238'000);
  // a pulse must be longer than the bound
  EXPECT_FALSE(pulse_seen_across_update(237'999, d));
  EXPECT_FALSE(pulse_seen_across_update(238'000, d));
  EXPECT_TRUE(pulse_seen_across_update(238'001, d));
  // the 18 ms cam is lost across any update (even with 0 KB: 75 ms alone exceeds it)
  EXPECT_FALSE(pulse_seen_across_update(cam_pulse_duration(50, 10), min_signal_duration({})));
  EXPECT_EQ(min_signal_duration({}).total, 75'000);
}

// ---- T8: link-up time --------------------------------------------------------------------------

TEST(HUpdateTiming, T8_LinkUpTime) {
  // 2 MB · 1 s + 3 s = 5 s
  EXPECT_EQ(link_up_time(2048, 3'000'000), 5'000'000);
  // 512 KB = 0.5 MB → 0.5 s + 3 s
  EXPECT_EQ(link_up_time(512, 3'000'000), 3'500'000);
  // 1 KB = 1 000 000 / 1024 = 976.5625 µs → 977 µs (rounded up) + base 0
  EXPECT_EQ(link_up_time(1, 0), 977);
  // under load up to 1 min per MB: 2 MB · 60 s + 5 s = 125 s
  EXPECT_EQ(link_up_time(2048, 5'000'000, 60'000'000), 125'000'000);
}

// ---- the switchover planner's figures as inputs -------------------------------------------------

TEST(HUpdateTiming, InputsFromSwitchoverPlanRoundUp) {
  redundancy::SwitchoverPlan sp;
  sp.line[0].t_tr = 25 * bus::kTicksPerMs;      // 25 ms exactly
  sp.line[1].t_tr = 25 * bus::kTicksPerMs + 1;  // one tick more → 25.001 ms
  sp.system_t_dp_um[0] = 100 * bus::kTicksPerMs;
  sp.system_t_dp_um[1] = 90 * bus::kTicksPerMs;
  sp.max_t_slave_um = 30 * bus::kTicksPerMs;
  const DpSystemTiming s = dp_system_from_switchover_plan("A/B", sp, 1'250'000);
  EXPECT_EQ(s.name, "A/B");
  EXPECT_EQ(s.t_tr, 25'001);
  EXPECT_EQ(s.t_dp_um, 100'000);
  EXPECT_EQ(s.t_slave_um, 30'000);
  EXPECT_EQ(s.t_pto, 1'250'000);
  EXPECT_EQ(ticks_to_us_ceil(0), 0);
  EXPECT_EQ(ticks_to_us_ceil(3'636), 1);
  EXPECT_EQ(ticks_to_us_ceil(3'637), 2);
}

TEST(HUpdateTiming, FormatMs) {
  EXPECT_EQ(format_ms(0), "0 ms");
  EXPECT_EQ(format_ms(1), "0.001 ms");
  EXPECT_EQ(format_ms(194'000), "194 ms");
  EXPECT_EQ(format_ms(1'508'600), "1508.6 ms");
  EXPECT_EQ(format_ms(-30'000), "-30 ms");
  EXPECT_EQ(format_ms(-5), "-0.005 ms");
}

}  // namespace
}  // namespace pbvbus::devices
