// What the real S7-400H refuses, refused by the loader (scenario/include/pbvbus/scenario/
// h_config_rules.hpp; docs/h-config-rules.md): one test per refused configuration (seeds-digest
// §11 D4, D5, C1, C4, S10), each with its FILE:LINE:COLUMN message, and the configurations
// just inside each limit, which load. Limits are the manual's (000 = English S7-400H manual,
// 001 = the Russian edition, by line), not the code's.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

const std::string kFile = std::string(PBVBUS_SOURCE_DIR) + "/examples/h.textproto";

// Lines 1..7; a test appends its entries from line 8 on.
const std::string kBase = R"(name: "h"
duration: "1s"
line { name: "DP_A" baud: "1.5M" }
line { name: "DP_B" baud: "1.5M" }
dp_master { address: 1 line: "DP_A" }
dp_master { address: 1 line: "DP_B" }
switched_station { system: "H-DP 1" address: 3 gsd: "gsd/PBVB0A10.gsd" modules: ["16DI DC24V", "16DO DC24V/0.5A"] }
)";

/// The redundant system "H-DP 1" over DP_A/DP_B with `places` (place_a/place_b text).
std::string rms(const std::string& places = "") {
  return "redundant_master_system { name: \"H-DP 1\" line_a: \"DP_A\" master_a: 1 line_b: \"DP_B\" master_b: 1" +
         (places.empty() ? std::string() : " " + places) + " }\n";
}
/// A simulated h_system "H" driving "H-DP 1"; `cpu` goes into its cpu part.
std::string h(const std::string& cpu = "") {
  return "h_system { name: \"H\" dp_system { system: \"H-DP 1\" t_pto: \"2s\" } cpu {" +
         (cpu.empty() ? std::string() : " " + cpu) + " } }\n";
}

LoadResult load(const std::string& more) { return parse_scenario(kBase + more, kFile); }

/// The errors of a whole file's text, "h.textproto:LINE:COLUMN: message".
std::vector<std::string> errors_of(const std::string& text) {
  std::vector<std::string> out;
  for (const auto& d : parse_scenario(text, kFile).errors) {
    std::string s = d.str();
    if (s.rfind(kFile, 0) == 0) s = "h.textproto" + s.substr(kFile.size());
    out.push_back(s);
  }
  return out;
}
std::vector<std::string> errors(const std::string& more) { return errors_of(kBase + more); }

std::string all(const std::vector<std::string>& e) {
  std::string s;
  for (const auto& x : e) s += x + "\n";
  return s;
}

/// A modular GSD (examples/gsd/PBVB0A02.gsd with 244 octets per direction) plus modules for
/// the limits: "128 in" (special format, 64 words), "130 in" (128 + 2 octets in one slot),
/// "64 in consistent AKF" (two general identifiers of 16 words, consistent), "64 in consistent
/// SKF" (one special identifier of 32 words, consistent), "128 in consistent SKF" (64 words).
/// Returns its absolute path.
std::string limits_gsd() {
  static const std::string path = [] {
    std::ifstream in(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A02.gsd");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string t = ss.str();
    auto set = [&](const std::string& key, const std::string& from, const std::string& to) {
      const auto at = t.find(key + from);
      if (at != std::string::npos) t.replace(at, (key + from).size(), key + to);
    };
    set("Max_Input_Len           = ", "64", "244");
    set("Max_Output_Len          = ", "64", "244");
    set("Max_Data_Len            = ", "128", "488");
    t += "\nModule = \"128 in\" 0x40,0x7F\n7\nEndModule\n"
         "Module = \"130 in\" 0x40,0x7F,0x40,0x01\n8\nEndModule\n"
         "Module = \"64 in consistent AKF\" 0xDF,0xDF\n9\nEndModule\n"
         "Module = \"64 in consistent SKF\" 0x40,0xDF\n10\nEndModule\n"
         "Module = \"128 in consistent SKF\" 0x40,0xFF\n11\nEndModule\n";
    const auto dir = std::filesystem::temp_directory_path() / ("pbvbus_h_refusals_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    const auto p = dir / "PBVBHR01.gsd";
    std::ofstream(p) << t;
    return p.string();
  }();
  return path;
}

/// `n` one-sided slaves (examples/gsd/PBVB0A01.gsd) on `line`'s master 1 from address `first`,
/// one line each.
std::string slaves(const std::string& line, int first, int n) {
  std::string s;
  for (int k = 0; k < n; ++k)
    s += "dp_slave { address: " + std::to_string(first + k) + " line: \"" + line +
         "\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n";
  return s;
}

TEST(HRefusals, TheBaseConfigurationLoads) {
  const auto r = load(rms() + h());
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
}

// ---- D4: no multi-master operation in Redundant mode (001 L14070-14074; table B-1
// L13653-13655: standard CPU yes, Solo yes, Redundant no) ----

TEST(HRefusals, D4_ASecondDpMasterOnARedundantLineIsRefused) {
  // Line 8: `dp_master { ` is 12 columns, `address: 2 ` 11 more: `line` at column 24.
  EXPECT_EQ(errors("dp_master { address: 2 line: \"DP_A\" }\n" + rms() + h()),
            (std::vector<std::string>{
                "h.textproto:8:24: dp_master 2 on line \"DP_A\": a second DP master on a line of "
                "redundant_master_system \"H-DP 1\" of h_system \"H\": an H-system's DP master system runs no "
                "multi-master operation in Redundant mode (S7-400H manual 001 L14070-14074, L13653-13655, D4)"}));
}

TEST(HRefusals, D4_APlainFdlMasterOnARedundantLineIsRefused) {
  // Line 8: `master { ` is 9 columns, `address: 5 ` 11 more: `line` at column 21.
  EXPECT_EQ(errors("master { address: 5 line: \"DP_B\" }\n" + rms() + h()),
            (std::vector<std::string>{
                "h.textproto:8:21: master on line \"DP_B\": a second master on a line of "
                "redundant_master_system \"H-DP 1\" of h_system \"H\": an H-system's DP master system runs no "
                "multi-master operation in Redundant mode (S7-400H manual 001 L14070-14074, L13653-13655, D4)"}));
}

// D4, equidistance: 001 L14085-14089 ("in a fault-tolerant system there is no equidistance for
// DP slaves"); table B-1 L13663-13666 (standard CPU yes, Solo no, Redundant no).
std::string equidistant_base() {
  std::string b = kBase;
  const std::string m = "dp_master { address: 1 line: \"DP_A\" }";
  b.replace(b.find(m), m.size(), "dp_master { address: 1 line: \"DP_A\" equidistant_cycle: \"5ms\" }");
  return b;
}

TEST(HRefusals, D4_AnEquidistantMasterOfAnHSystemIsRefused) {
  // Line 5: `dp_master { address: 1 line: "DP_A" ` is 36 columns: the field at column 37.
  EXPECT_EQ(errors_of(equidistant_base() + rms() + h()),
            (std::vector<std::string>{
                "h.textproto:5:37: dp_master 1 on line \"DP_A\": equidistant_cycle on a DP master of "
                "redundant_master_system \"H-DP 1\" of h_system \"H\": an H-system has no equidistance of DP "
                "slaves (S7-400H manual 001 L14085-14089, L13663-13666, D4)"}));
}

TEST(HRefusals, D4_AnEquidistantMasterOfARedundantSystemWithoutAnHSystemLoads) {
  // A plain PI 2.212 system: equidistance is the standard CPU's "yes" of table B-1.
  const auto r = parse_scenario(equidistant_base() + rms(), kFile);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  EXPECT_EQ(r.plan->dp_masters[0].params.equidistant_cycle, 5 * bus::kTicksPerMs);
}

TEST(HRefusals, D4_ASecondMasterOnARedundantSystemWithoutAnHSystemLoads) {
  // Without an h_system the redundant system is a plain PI 2.212 system: multi-master is the
  // standard CPU's "yes" of table B-1.
  const auto r = load("dp_master { address: 2 line: \"DP_A\" }\n" + rms());
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
}

// ---- D5 ----

// ---- D4: SFC 11 DPSYC_FR and SFC 12 D_ACT_DP are not supported by an H CPU (001 Appendix B
// L14091-14096, L14098-14103; table B-1 L13668-13672: standard CPU yes, Solo no, Redundant no;
// 000 L4112, L4262). The error is at the call in the program (line 10 / 11, column 3). ----

/// h_system "H" with a program of `calls` (one per line from line 10 on).
std::string h_program(const std::string& calls) {
  return "h_system { name: \"H\" dp_system { system: \"H-DP 1\" t_pto: \"2s\" } cpu { } program {\n" + calls +
         "} }\n";
}

TEST(HRefusals, D4_Sfc11DpsycFrInAnHProgramIsRefused) {
  EXPECT_EQ(errors(rms() + h_program("  dpsyc_fr { line: \"DP_A\" group: 1 mode: 32 }\n")),
            (std::vector<std::string>{
                "h.textproto:10:3: h_system \"H\": the program calls SFC 11 DPSYC_FR; an H CPU does not support "
                "it, in Solo and in Redundant mode (no SYNC/FREEZE of DP slave groups) (S7-400H manual 001 "
                "L14091-14096, L13668-13672; 000 L4112, L4262, D4)"}));
}

TEST(HRefusals, D4_Sfc12DActDpInAnHProgramIsRefused) {
  EXPECT_EQ(errors(rms() + h_program("  dprd_dat { laddr: 0 record: 100 length: 2 }\n"
                                     "  d_act_dp { line: \"DP_A\" station: 3 mode: 2 }\n")),
            (std::vector<std::string>{
                "h.textproto:11:3: h_system \"H\": the program calls SFC 12 D_ACT_DP; an H CPU does not support "
                "it (DP slaves cannot be deactivated and activated) (S7-400H manual 001 L14098-14103, D4)"}));
}

TEST(HRefusals, C1_Sfc14And15InAnHProgramLoad) {
  // The length rule is the run's RET_VAL W#16#80B1 (tests/controllers/s7h), not a load error.
  const auto r = load(rms() + h_program("  dprd_dat { laddr: 0 record: 100 length: 2 ret_val: 98 }\n"
                                        "  dpwr_dat { laddr: 0 record: 100 length: 3 ret_val: 96 }\n"));
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  ASSERT_EQ(r.plan->h_systems.size(), 1u);
  ASSERT_TRUE(r.plan->h_systems[0].runtime);
  const auto& spec = r.plan->h_systems[0].runtime->program;
  ASSERT_EQ(spec.dprd_dat.size(), 1u);
  ASSERT_EQ(spec.dpwr_dat.size(), 1u);
  EXPECT_EQ(spec.dpwr_dat[0].length, 3u);
  EXPECT_EQ(spec.dpwr_dat[0].ret_val, std::optional<std::uint32_t>(96));
}

TEST(HRefusals, D5_X1TakesAtMost32Slaves) {
  // X1 on both sides: the switched station (address 3) + 31 one-sided slaves = 32 on DP_A.
  const std::string x1 = "place_a { interface: X1_MPI_DP } place_b { interface: X1_MPI_DP }";
  const auto ok = load(rms(x1) + slaves("DP_A", 10, 31) + h());
  ASSERT_TRUE(ok.ok()) << ok.errors[0].str();
  // 32 one-sided slaves: the 33rd slave of DP_A's master is dp_slave 41 (10 + 31), on line
  // 9 + 31 = 40; `dp_slave { ` is 11 columns, so `address` at column 12.
  const auto e = errors(rms(x1) + slaves("DP_A", 10, 32) + h());
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_EQ(e[0],
            "h.textproto:40:12: dp_slave 41 on line \"DP_A\": 33 slaves on the DP master at rack 0 X1 (MPI/DP) in "
            "slot 3 of redundant_master_system \"H-DP 1\" of h_system \"H\"; CPU 417-4H's X1 (MPI/DP) serves at "
            "most 32 (S7-400H manual 001 L12762, L12816; 000 L1724, D5)");
}

TEST(HRefusals, D5_X2OfA414_4HTakesAtMost96Slaves) {
  const std::string cpu = "cpu_type: CPU_414_4H";
  const auto ok = load(rms() + slaves("DP_B", 4, 95) + h(cpu));  // 95 + the switched station
  ASSERT_TRUE(ok.ok()) << ok.errors[0].str();
  // 96 one-sided slaves: the 97th is dp_slave 4 + 95 = 99 on line 9 + 95 = 104.
  const auto e = errors(rms() + slaves("DP_B", 4, 96) + h(cpu));
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_EQ(e[0],
            "h.textproto:104:12: dp_slave 99 on line \"DP_B\": 97 slaves on the DP master at rack 1 X2 (DP) in slot "
            "3 of redundant_master_system \"H-DP 1\" of h_system \"H\"; CPU 414-4H's X2 (DP) serves at most 96 "
            "(S7-400H manual 001 L12001, L12054, D5)");
  // The same 97 on a 417-4H's X2 (125, 001 L12816) load.
  const auto r = load(rms() + slaves("DP_B", 4, 96) + h());
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
}

TEST(HRefusals, D5_MoreThan12DpMasterSystemsAreRefused) {
  std::string sys;
  for (int k = 0; k < 13; ++k)
    sys += " dp_system { name: \"S" + std::to_string(k) + "\" t_tr: \"10ms\" t_dp_um: \"10ms\" t_slave_um: \"10ms\" t_pto: \"2s\" }\n";
  // h_system on line 9, dp_system[0] on line 10, dp_system[12] on line 22 at column 2.
  const auto e = errors(rms() + "h_system { name: \"T\"\n" + sys + "}\n");
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_EQ(e[0],
            "h.textproto:22:2: h_system \"T\": 13 DP master systems; an H-system has at most 12 per subsystem (2 on "
            "the CPU's interfaces + 10 CP 443-5 Extended) (S7-400H manual 000 L1722, D5)");
}

TEST(HRefusals, D5_APaRateOnARedundantLineIsRefused) {
  // No slaves (a GSD without 31.25_supp is refused by the DP layer first); both lines at one
  // rate (a redundant system's rule).
  const std::string text = R"(name: "pa"
duration: "1s"
line { name: "DP_A" baud: "31.25k" }
line { name: "DP_B" bit_rate: 31250 }
dp_master { address: 1 line: "DP_A" }
dp_master { address: 1 line: "DP_B" }
)" + rms() + h();
  const auto e = errors_of(text);
  // `line { name: "DP_A" ` is 20 columns: `baud` at column 21 of line 3, `bit_rate` of line 4.
  EXPECT_EQ(e, (std::vector<std::string>{
                   "h.textproto:3:21: line \"DP_A\" of redundant_master_system \"H-DP 1\" of h_system \"H\": 31.25 "
                   "kbit/s is PROFIBUS PA's rate; an H-system's DP master runs 9.6 kbit/s to 12 Mbit/s (S7-400H "
                   "manual 000 L2030-2046, D5)",
                   "h.textproto:4:21: line \"DP_B\" of redundant_master_system \"H-DP 1\" of h_system \"H\": 31.25 "
                   "kbit/s is PROFIBUS PA's rate; an H-system's DP master runs 9.6 kbit/s to 12 Mbit/s (S7-400H "
                   "manual 000 L2030-2046, D5)"}));
}

TEST(HRefusals, D5_MoreThan128OctetsInOneSlotAreRefused) {
  const std::string g = limits_gsd();
  const auto ok = load(rms() + "dp_slave { address: 10 line: \"DP_A\" gsd: \"" + g + "\" master: 1 modules: [\"128 in\"] }\n" + h("input_bytes: 512"));
  ASSERT_TRUE(ok.ok()) << ok.errors[0].str();
  // Line 9: the module list element 1 ("130 in").
  const auto e = errors(rms() + "dp_slave { address: 10 line: \"DP_A\" gsd: \"" + g +
                        "\" master: 1 modules: [\"8DI DC24V\", \"130 in\"] }\n" + h("input_bytes: 512"));
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_NE(e[0].find("h.textproto:9:"), std::string::npos) << e[0];
  EXPECT_NE(e[0].find(": dp_slave 10 module \"130 in\" of redundant_master_system \"H-DP 1\" of h_system \"H\": 130 "
                      "input octets in one slot; an H-system's DP master takes at most 128 per slot (S7-400H manual "
                      "001 L12006-12010, D5)"),
            std::string::npos)
      << e[0];
}

TEST(HRefusals, D5_MoreThan244OctetsPerSlaveAreRefusedByTheDpLayer) {
  // 128 + 128 = 256 input octets: the DP layer refuses the slave before the H rules (its
  // configuration is over the standard's 244, IEC 61158-6; 001 L12006 gives the same limit).
  const auto e = errors(rms() + "dp_slave { address: 10 line: \"DP_A\" gsd: \"" + limits_gsd() +
                        "\" master: 1 modules: [\"128 in\", \"128 in\"] }\n" + h("input_bytes: 512"));
  ASSERT_FALSE(e.empty());
  EXPECT_NE(e[0].find("h.textproto:9:"), std::string::npos) << all(e);
}

// ---- C1: consistent blocks (001 §4.10.4 L3387-3405): SKF 64 words = 128 B, AKF 16 words = 32 B ----

TEST(HRefusals, C1_AConsistentModuleOver32OctetsInTheGeneralFormatIsRefused) {
  const std::string g = limits_gsd();
  auto slave = [&](const std::string& module) {
    return rms() + "dp_slave { address: 10 line: \"DP_A\" gsd: \"" + g + "\" master: 1 modules: [\"" + module +
           "\"] }\n" + h();
  };
  // 64 octets consistent in one special identifier, and 128: within SKF's 128.
  for (const char* m : {"64 in consistent SKF", "128 in consistent SKF"}) {
    const auto r = load(slave(m));
    ASSERT_TRUE(r.ok()) << m << ": " << r.errors[0].str();
  }
  const auto e = errors(slave("64 in consistent AKF"));
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_NE(e[0].find("h.textproto:9:"), std::string::npos) << e[0];
  EXPECT_NE(e[0].find(": dp_slave 10 module \"64 in consistent AKF\" of redundant_master_system \"H-DP 1\" of "
                      "h_system \"H\": 64 input octets consistent over the whole length; with the general "
                      "identifier format (AKF) at most 32 (S7-400H manual 001 §4.10.4 L3387-3405, C1)"),
            std::string::npos)
      << e[0];
}

// ---- C4: process images (001 §9.2.3 L8067-8072; sizes 001 L11664-11666, L12405-12407) ----

TEST(HRefusals, C4_AModuleStraddlingTheProcessImageIsRefused) {
  const std::string g = limits_gsd();
  // PII: the switched station 3 first (16DI: IB 0..1), then dp_slave 10's "128 in" at IB 2..129,
  // dp_slave 11's (line 10) at IB 130..257 across a 414-4H's default 256 octets.
  const std::string s =
      "dp_slave { address: 10 line: \"DP_A\" gsd: \"" + g + "\" master: 1 modules: [\"128 in\"] }\n"
      "dp_slave { address: 11 line: \"DP_B\" gsd: \"" + g + "\" master: 1 modules: [\"128 in\"] }\n";
  const auto e = errors(rms() + s + h("cpu_type: CPU_414_4H"));
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_NE(e[0].find("h.textproto:10:"), std::string::npos) << e[0];
  EXPECT_NE(e[0].find(": h_system \"H\": dp_slave 11 module \"128 in\" (input octets 130..257) straddles the end "
                      "of the input process image at 256 octets: a module lies wholly inside or wholly outside it "
                      "(S7-400H manual 001 §9.2.3 L8067-8072, C4)"),
            std::string::npos)
      << e[0];
  // A 417-4H's default 1024, or a 414-4H's image set to 258, holds it; 130 leaves the second
  // module wholly outside (direct access only), which the CPU allows.
  for (const char* cpu : {"", "cpu_type: CPU_414_4H input_bytes: 258", "cpu_type: CPU_414_4H input_bytes: 130"}) {
    const auto r = load(rms() + s + h(cpu));
    ASSERT_TRUE(r.ok()) << cpu << ": " << r.errors[0].str();
  }
}

TEST(HRefusals, C4_AProcessImageLargerThanTheCpuTypeIsRefused) {
  // Line 9 (`h_system {` ... `cpu { `): output_bytes after `cpu_type: CPU_414_4H `.
  const auto e = errors(rms() + h("cpu_type: CPU_414_4H output_bytes: 8193"));
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_NE(e[0].find("h.textproto:9:"), std::string::npos) << e[0];
  EXPECT_NE(e[0].find(": h_system \"H\": a process image of 8193 octets of outputs is more than a CPU 414-4H has "
                      "(8192 octets; S7-400H manual 001 L11664-11666, C4)"),
            std::string::npos)
      << e[0];
  const auto r = load(rms() + h("output_bytes: 16384"));  // a 417-4H's 16 KB
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
}

// ---- S10: symmetric placement (000 L1782-1785, L2362-2364; 001 L5580-5587) ----

TEST(HRefusals, S10_AsymmetricMasterPlacementIsRefused) {
  // Line 8: `place_b` follows `redundant_master_system { name: "H-DP 1" line_a: "DP_A"
  // master_a: 1 line_b: "DP_B" master_b: 1 place_a { interface: X2_DP } `.
  const std::string head =
      "redundant_master_system { name: \"H-DP 1\" line_a: \"DP_A\" master_a: 1 line_b: \"DP_B\" master_b: 1 ";
  const std::string pa = "place_a { interface: X2_DP } ";
  const auto e = errors(head + pa + "place_b { interface: CP_443_5_EXT slot: 5 } }\n" + h());
  const int col = static_cast<int>(head.size() + pa.size()) + 1;
  EXPECT_EQ(e, (std::vector<std::string>{
                   "h.textproto:8:" + std::to_string(col) +
                   ": redundant_master_system \"H-DP 1\" of h_system \"H\": asymmetric placement: line A's master "
                   "at rack 0 X2 (DP) in slot 3, line B's at rack 1 CP 443-5 Extended in slot 5; both masters sit "
                   "at the same interface in the same slot (S7-400H manual 000 L1782-1785, L2362-2364; 001 "
                   "L5580-5587, S10)"}));
  // Only place_a given (a CP), place_b the default X2: the error is at place_a, line 8 column
  // head.size() + 1.
  const auto one = errors(head + "place_a { interface: CP_443_5_EXT slot: 5 } }\n" + h());
  ASSERT_EQ(one.size(), 1u) << all(one);
  EXPECT_EQ(one[0].rfind("h.textproto:8:" + std::to_string(head.size() + 1) +
                             ": redundant_master_system \"H-DP 1\" of h_system \"H\": asymmetric placement: line A's "
                             "master at rack 0 CP 443-5 Extended in slot 5, line B's at rack 1 X2 (DP) in slot 3",
                         0),
            0u)
      << one[0];
  // Two CPs in slot 5 load, as two X2 do.
  const auto r = load(rms("place_a { interface: CP_443_5_EXT slot: 5 } place_b { interface: CP_443_5_EXT slot: 5 }") + h());
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
}

TEST(HRefusals, S10_DifferentSlotsOfTheSameInterfaceAreRefused) {
  const auto e = errors(rms("place_a { interface: CP_443_5_EXT slot: 5 } place_b { interface: CP_443_5_EXT slot: 6 }") + h());
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_NE(e[0].find("asymmetric placement: line A's master at rack 0 CP 443-5 Extended in slot 5, line B's at "
                      "rack 1 CP 443-5 Extended in slot 6"),
            std::string::npos)
      << e[0];
}

TEST(HRefusals, S10_BothMastersInOneRackAreRefused) {
  const auto e = errors(rms("place_b { rack: 0 }") + h());
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_NE(e[0].find(": redundant_master_system \"H-DP 1\" of h_system \"H\": both DP masters in rack 0: a "
                      "redundant DP master system has one master in each central rack (S7-400H manual 000 "
                      "L2362-2364, S10)"),
            std::string::npos)
      << e[0];
  const auto x = errors(rms("place_a { rack: 2 }") + h());
  ASSERT_EQ(x.size(), 1u) << all(x);
  EXPECT_NE(x[0].find("place_a rack 2 is not a central rack"), std::string::npos) << x[0];
  // The lines swapped between the racks load.
  const auto r = load(rms("place_a { rack: 1 } place_b { rack: 0 }") + h());
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
}

TEST(HRefusals, S10_X1AsDpMasterAndMpiInterfaceIsRefused) {
  const std::string text = "line { name: \"MPI\" kind: MPI }\n" +
                           rms("place_a { interface: X1_MPI_DP } place_b { interface: X1_MPI_DP }") +
                           h("mpi { line: \"MPI\" }");
  const auto e = errors(text);
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_NE(e[0].find("X1 is the CPUs' MPI interface (cpu.mpi), so it cannot also be a DP master"), std::string::npos)
      << e[0];
}

TEST(HRefusals, S10_OneInterfaceServesOneMasterSystem) {
  // A second redundant system on DP_C/DP_D at the default X2 as well.
  const std::string more = R"(line { name: "DP_C" }
line { name: "DP_D" }
dp_master { address: 1 line: "DP_C" }
dp_master { address: 1 line: "DP_D" }
redundant_master_system { name: "H-DP 2" line_a: "DP_C" master_a: 1 line_b: "DP_D" master_b: 1 }
)";
  const std::string h2 =
      "h_system { name: \"H\" dp_system { system: \"H-DP 1\" t_pto: \"2s\" } dp_system { system: \"H-DP 2\" t_pto: "
      "\"2s\" } cpu { } }\n";
  const auto e = errors(more + rms() + h2);
  ASSERT_EQ(e.size(), 1u) << all(e);
  EXPECT_NE(e[0].find("redundant_master_system \"H-DP 2\" of h_system \"H\": rack 0 X2 (DP) in slot 3 is already "
                      "the DP master of redundant_master_system \"H-DP 1\": one interface, one DP master system "
                      "(S7-400H manual 000 L1722, S10)"),
            std::string::npos)
      << e[0];
  const std::string h_dp2_on_cp =
      R"(line { name: "DP_C" }
line { name: "DP_D" }
dp_master { address: 1 line: "DP_C" }
dp_master { address: 1 line: "DP_D" }
redundant_master_system { name: "H-DP 2" line_a: "DP_C" master_a: 1 line_b: "DP_D" master_b: 1 place_a { interface: CP_443_5_EXT slot: 5 } place_b { interface: CP_443_5_EXT slot: 5 } }
)";
  const auto ok = load(h_dp2_on_cp + rms() + h2);
  ASSERT_TRUE(ok.ok()) << ok.errors[0].str();
}

}  // namespace
}  // namespace pbvbus::tools
