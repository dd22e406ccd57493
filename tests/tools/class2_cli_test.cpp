// `pbvbus run --dp2 SPEC`: parsing of the class-2 request specs and options (good and bad), and
// the report line format.

#include "pbvbus/tools/class2_cli.hpp"

#include <gtest/gtest.h>

namespace pbvbus::tools {
namespace {

Class2Request ok(std::string_view spec) {
  std::string err;
  auto r = parse_class2_spec(spec, err);
  EXPECT_TRUE(r) << spec << ": " << err;
  EXPECT_EQ(err, "");
  return r ? *r : Class2Request{};
}

std::string bad(std::string_view spec) {
  std::string err;
  auto r = parse_class2_spec(spec, err);
  EXPECT_FALSE(r) << spec;
  return err;
}

TEST(Class2Spec, SimpleServices) {
  Class2Request r = ok("1s:get_cfg:5");
  EXPECT_EQ(r.at, bus::kTicksPerSecond);
  EXPECT_EQ(r.op, Class2Op::GetCfg);
  EXPECT_EQ(r.station, 5);
  r = ok("250ms:slave_diag:126");
  EXPECT_EQ(r.at, 250 * bus::kTicksPerMs);
  EXPECT_EQ(r.op, Class2Op::SlaveDiag);
  EXPECT_EQ(r.station, 126);
  EXPECT_EQ(ok("2s:rd_inp:3").op, Class2Op::RdInp);
  EXPECT_EQ(ok("2s:rd_outp:0").op, Class2Op::RdOutp);
}

TEST(Class2Spec, SetSlaveAdd) {
  Class2Request r = ok("3s:set_slave_add:126:new=7,ident=0x0A01");
  EXPECT_EQ(r.op, Class2Op::SetSlaveAdd);
  EXPECT_EQ(r.station, 126);
  EXPECT_EQ(r.new_address, 7);
  EXPECT_EQ(r.ident, 0x0A01);
  EXPECT_FALSE(r.no_add_chg);
  r = ok("3s:set_slave_add:126:ident=2561,new=125,no_add_chg=1");
  EXPECT_EQ(r.ident, 0x0A01);
  EXPECT_EQ(r.new_address, 125);
  EXPECT_TRUE(r.no_add_chg);
}

TEST(Class2Spec, ReadAndWrite) {
  Class2Request r = ok("1s:read:4:slot=1,index=2,len=8");
  EXPECT_EQ(r.op, Class2Op::Read);
  EXPECT_EQ(r.station, 4);
  EXPECT_EQ(r.slot, 1);
  EXPECT_EQ(r.index, 2);
  EXPECT_EQ(r.length, 8);
  r = ok("1s:write:4:slot=1,index=2,data=0102A0");
  EXPECT_EQ(r.op, Class2Op::Write);
  EXPECT_EQ(r.data, (std::vector<std::uint8_t>{0x01, 0x02, 0xA0}));
  r = ok("1s:write:4:slot=0,index=255,data=0xff");
  EXPECT_EQ(r.index, 255);
  EXPECT_EQ(r.data, (std::vector<std::uint8_t>{0xFF}));
}

TEST(Class2Spec, ErrorsNameTheBadPart) {
  EXPECT_EQ(bad("1s:get_cfg"),
            "--dp2 '1s:get_cfg': expected TIME:SERVICE:STATION[:KEY=VALUE,...], e.g. 1s:get_cfg:5");
  EXPECT_EQ(bad("soon:get_cfg:5"), "--dp2 'soon:get_cfg:5': bad time 'soon' (expected e.g. 1s, 250ms)");
  EXPECT_EQ(bad("1s:get_config:5"),
            "--dp2 '1s:get_config:5': unknown service 'get_config' (get_cfg, slave_diag, rd_inp, "
            "rd_outp, set_slave_add, read, write)");
  EXPECT_EQ(bad("1s:get_cfg:127"), "--dp2 '1s:get_cfg:127': bad station '127' (expected an address 0..126)");
  EXPECT_EQ(bad("1s:get_cfg:x5"), "--dp2 '1s:get_cfg:x5': bad station 'x5' (expected an address 0..126)");
  EXPECT_EQ(bad("1s:get_cfg:5:slot=1"), "--dp2 '1s:get_cfg:5:slot=1': unknown argument 'slot' for get_cfg");
  EXPECT_EQ(bad("1s:read:4:slot=1,index=2"), "--dp2 '1s:read:4:slot=1,index=2': read needs len=");
  EXPECT_EQ(bad("1s:read:4:slot=1,index=2,len=0"),
            "--dp2 '1s:read:4:slot=1,index=2,len=0': bad value '0' of len (expected a length 1..240)");
  EXPECT_EQ(bad("1s:read:4:slot=1,index=2,len=241"),
            "--dp2 '1s:read:4:slot=1,index=2,len=241': bad value '241' of len (expected a length 1..240)");
  EXPECT_EQ(bad("1s:write:4:slot=1,index=2,data=012"),
            "--dp2 '1s:write:4:slot=1,index=2,data=012': bad value '012' of data (expected 1..240 octets "
            "in hex, e.g. 0102A0)");
  EXPECT_EQ(bad("1s:write:4:slot=1,index=2,data=zz"),
            "--dp2 '1s:write:4:slot=1,index=2,data=zz': bad value 'zz' of data (expected 1..240 octets "
            "in hex, e.g. 0102A0)");
  EXPECT_EQ(bad("3s:set_slave_add:126:new=126,ident=1"),
            "--dp2 '3s:set_slave_add:126:new=126,ident=1': bad value '126' of new (expected an address "
            "0..125)");
  EXPECT_EQ(bad("3s:set_slave_add:126:new=7"), "--dp2 '3s:set_slave_add:126:new=7': set_slave_add needs ident=");
  EXPECT_EQ(bad("3s:set_slave_add:126:new=7,new=8,ident=1"),
            "--dp2 '3s:set_slave_add:126:new=7,new=8,ident=1': 'new' given twice");
  EXPECT_EQ(bad("3s:set_slave_add:126:new=7,ident=1,no_add_chg=2"),
            "--dp2 '3s:set_slave_add:126:new=7,ident=1,no_add_chg=2': bad value '2' of no_add_chg "
            "(expected 0 or 1)");
  EXPECT_EQ(bad("1s:read:4:slot1"), "--dp2 '1s:read:4:slot1': bad argument 'slot1' (expected KEY=VALUE)");
  EXPECT_EQ(bad("1s:get_cfg:5:a=1:b=2"),
            "--dp2 '1s:get_cfg:5:a=1:b=2': expected TIME:SERVICE:STATION[:KEY=VALUE,...], e.g. 1s:get_cfg:5");
}

TEST(Class2Spec, RunOptions) {
  Class2Options o;
  std::string err;
  const Args args = {"--dp2", "1s:get_cfg:5", "--dp2-line", "A", "--dp2-address", "3", "--fast", "--dp2"};
  std::size_t i = 0;
  EXPECT_EQ(parse_class2_arg(args, i, o, err), Class2ArgResult::Taken);
  EXPECT_EQ(i, 1u);
  i = 2;
  EXPECT_EQ(parse_class2_arg(args, i, o, err), Class2ArgResult::Taken);
  i = 4;
  EXPECT_EQ(parse_class2_arg(args, i, o, err), Class2ArgResult::Taken);
  i = 6;
  EXPECT_EQ(parse_class2_arg(args, i, o, err), Class2ArgResult::NotMine);
  EXPECT_EQ(i, 6u);
  i = 7;
  EXPECT_EQ(parse_class2_arg(args, i, o, err), Class2ArgResult::Error);
  EXPECT_EQ(err, "--dp2 needs a value");
  ASSERT_EQ(o.requests.size(), 1u);
  EXPECT_EQ(o.line, "A");
  EXPECT_EQ(o.address, 3);
  const Args bad_addr = {"--dp2-address", "127"};
  i = 0;
  EXPECT_EQ(parse_class2_arg(bad_addr, i, o, err), Class2ArgResult::Error);
  EXPECT_EQ(err, "bad --dp2-address '127' (expected 0..126)");
}

TEST(Class2Spec, ReportLine) {
  Class2Outcome o;
  o.at = bus::kTicksPerSecond;
  o.done = bus::kTicksPerSecond + 3 * bus::kTicksPerMs;
  o.op = Class2Op::GetCfg;
  o.station = 5;
  o.status = "OK";
  o.bytes = {0x11, 0x21};
  o.text = "2 B in, 2 B out";
  EXPECT_EQ(format_class2_line(o), "1.000 s get_cfg 5: OK 11 21 (2 B in, 2 B out) at 1.003 s");
  o.done = 0;
  o.status = "pending";
  o.bytes.clear();
  o.text.clear();
  EXPECT_EQ(format_class2_line(o), "1.000 s get_cfg 5: pending");
}

}  // namespace
}  // namespace pbvbus::tools
