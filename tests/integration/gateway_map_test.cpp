// `pbvbus gateway map` through the binary (tools/src/cmd_gateway.cpp) on the shipped
// examples/gateway.textproto: the CSV rows of dp-basic's slave 4 and the other formats.
//
// Slave 4 (PBVB0A02.gsd) has modules "8DI DC24V" (1 input octet), "8DO DC24V/0.5A" (1 output
// octet), "2AO U/I 16 bit" (4 output octets). Each module starts on a new register
// (docs/gateway-modbus.md):
//   - input registers: 8DI at register 0, (1 + 1) / 2 = 1 register (octet 0 in the high byte);
//   - holding registers: 8DO at register 0, 1 register; 2AO after it at register 1,
//     4 / 2 = 2 registers (output octets 1..4);
//   - discrete inputs: input octet 0 -> bits 0 * 8 = 0 .. 7 (8 bits); coils: output octet 0 ->
//     bits 0..7, output octets 1..4 -> bits 1 * 8 = 8 .. 8 + 4 * 8 - 1 = 39 (32 bits).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace {

const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";
const std::string kExample = PBVBUS_SOURCE_DIR "/examples/gateway.textproto";

std::pair<int, std::string> run(const std::string& args, bool with_stderr = false) {
  std::string out;
  FILE* p = ::popen((kBinary + " " + args + (with_stderr ? " 2>&1" : " 2>/dev/null")).c_str(), "r");
  if (p == nullptr) return {-1, ""};
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

bool has_line(const std::string& text, const std::string& line) {
  return ("\n" + text).find("\n" + line + "\n") != std::string::npos;
}

TEST(GatewayMap, CsvRowsOfSlave4) {
  const auto [rc, csv] = run("gateway map " + kExample + " --csv");
  ASSERT_EQ(rc, 0) << csv;
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "unit,table,first_address,count,slave,slot,module,data_type,description");
  for (const char* row : {
           "4,input_register,0,1,4,0,8DI DC24V,BYTES AB CD,1 input octets from octet 0",
           "4,discrete_input,0,8,4,0,8DI DC24V,BIT,\"input bits, octet x 8 + bit\"",
           "4,holding_register,0,1,4,1,8DO DC24V/0.5A,BYTES AB CD,1 output octets from octet 0",
           "4,coil,0,8,4,1,8DO DC24V/0.5A,BIT,\"output bits, octet x 8 + bit\"",
           "4,holding_register,1,2,4,2,2AO U/I 16 bit,BYTES AB CD,4 output octets from octet 1",
           "4,coil,8,32,4,2,2AO U/I 16 bit,BIT,\"output bits, octet x 8 + bit\"",
           // slave 6, the 16-word station: 32 octets = 16 registers each way.
           "6,input_register,0,16,6,0,16 words in/out consistent,BYTES AB CD,32 input octets from octet 0",
           "6,holding_register,0,16,6,0,16 words in/out consistent,BYTES AB CD,32 output octets from octet 0",
       })
    EXPECT_TRUE(has_line(csv, row)) << row << "\n--- in ---\n" << csv;
}

TEST(GatewayMap, TextAndJsonNameTheGatewayAndItsCanMap) {
  const auto [rc, text] = run("gateway map " + kExample);
  ASSERT_EQ(rc, 0) << text;
  EXPECT_EQ(text.substr(0, text.find('\n')), "gateway gw (dp_master 1 on PROFIBUS_DP_1)");
  EXPECT_NE(text.find("\nModbus\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nCAN\n"), std::string::npos) << text;
  const auto [jrc, json] = run("gateway map " + kExample + " --json");
  ASSERT_EQ(jrc, 0) << json;
  EXPECT_EQ(json.rfind("{\"schema\":\"pbvbus.gateway.map/1\",\"gateways\":[{\"name\":\"gw\","
                       "\"served\":\"dp_master 1 on PROFIBUS_DP_1\",\"modbus\":{",
                       0),
            0u)
      << json;
}

TEST(GatewayMap, Errors) {
  auto [rc, out] = run("gateway map " + kExample + " --json --csv", true);
  EXPECT_EQ(rc, 2);
  EXPECT_EQ(out, "pbvbus gateway: --json and --csv exclude each other\nTry 'pbvbus gateway --help'.\n");
  std::tie(rc, out) = run("gateway map " + std::string(PBVBUS_SOURCE_DIR) + "/examples/dp-basic.textproto", true);
  EXPECT_EQ(rc, 2);
  EXPECT_EQ(out, "pbvbus gateway: " + std::string(PBVBUS_SOURCE_DIR) +
                     "/examples/dp-basic.textproto has no gateway\n");
  std::tie(rc, out) = run("gateway map " + kExample + " --gateway nope", true);
  EXPECT_EQ(rc, 2);
  EXPECT_EQ(out, "pbvbus gateway: " + kExample + " has no gateway \"nope\"\n");
}

}  // namespace
