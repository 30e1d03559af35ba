// The "contact" case key: wrong contact input fails with the key path (the contact mode a valid
// case runs: tests/physics/test_contact_case.cpp).
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"
#include "test_contact_common.hpp"

using namespace smpm;
using namespace smpm::contact_testing;

namespace {

std::string error_of(const nlohmann::json& doc) {
  try {
    build_case(doc, "impact.json");
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ContactCase, Errors) {
  auto d = impact_case();
  d["contact"]["type"] = "mult";
  EXPECT_EQ(error_of(d),
            "impact.json: contact.type: must be one of \"single\", \"multi\", got \"mult\" (did "
            "you mean \"multi\"?)");
  d = impact_case();
  d["contact"] = {{"type", "single"}, {"friction", 0.2}};
  EXPECT_NE(error_of(d).find("impact.json: contact.friction: friction needs \"type\": \"multi\""),
            std::string::npos);
  d = impact_case();
  d["contact"]["friction"] = -0.1;
  EXPECT_EQ(error_of(d), "impact.json: contact.friction: must be >= 0, got -0.1");
  d = impact_case();
  d["contact"]["frction"] = 0.1;
  EXPECT_NE(error_of(d).find("impact.json: contact.frction: unknown key (did you mean "
                             "\"friction\"?)"),
            std::string::npos);
  d = impact_case();
  d["contact"] = "multi";
  EXPECT_EQ(error_of(d), "impact.json: contact: expected an object, got a string");
}
