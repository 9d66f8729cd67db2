// `./bbw keys DIR` (scripts/bbw-keys.sh) checked with openssl: every identity verifies against
// the test CA and the rogue one does not, the governance and permissions documents are
// S/MIME-signed by the CA and say what docs/security.md claims, re-running keeps the keys, and
// the bbw_security helpers point at those files.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <string>

#include "bbw/dds/topics.hpp"
#include "bbw/security/dds_security.hpp"
#include "keys_fixture.hpp"

namespace {

using bbw::test::quote;
using bbw::test::read_text;
using bbw::test::run_shell;
using bbw::test::TempKeys;

class Keys : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { keys_ = std::make_unique<TempKeys>(); }
  static void TearDownTestSuite() { keys_.reset(); }
  void SetUp() override { ASSERT_EQ(keys_->status(), 0) << keys_->output(); }

  static std::string p(const std::string& rel) { return keys_->path(rel); }
  static bool verifies(const std::string& ca, const std::string& cert) {
    return run_shell("openssl verify -CAfile " + quote(ca) + " " + quote(cert)).status == 0;
  }
  static std::unique_ptr<TempKeys> keys_;
};
std::unique_ptr<TempKeys> Keys::keys_;

// The signed text of an S/MIME document if it verifies against `ca`, with CRLF undone.
// popen runs /bin/sh; PIPESTATUS needs bash.
std::string bash(const std::string& cmd) { return "bash -c " + quote(cmd); }

bool smime_ok(const std::string& ca, const std::string& p7s, std::string* text = nullptr) {
  const auto r = run_shell(bash("openssl smime -verify -text -in " + quote(p7s) + " -CAfile " + quote(ca) +
                                " 2>/dev/null | tr -d '\\r'; exit ${PIPESTATUS[0]}"));
  if (text != nullptr) *text = r.output;
  return r.status == 0;
}

TEST_F(Keys, EveryIdentityVerifiesAgainstTheCaAndTheRogueDoesNot) {
  for (const auto& id : bbw::security::identities()) {
    EXPECT_TRUE(verifies(p("ca/ca.pem"), p(id + "/cert.pem"))) << id;
    EXPECT_FALSE(verifies(p("rogue/ca/ca.pem"), p(id + "/cert.pem"))) << id;
  }
  EXPECT_FALSE(verifies(p("ca/ca.pem"), p("rogue/intruder/cert.pem")));
  EXPECT_TRUE(verifies(p("rogue/ca/ca.pem"), p("rogue/intruder/cert.pem")));
  // The CA is not fooled by a rogue CA with the same subject name.
  const auto ours = run_shell("openssl x509 -noout -subject -in " + quote(p("ca/ca.pem")));
  const auto theirs = run_shell("openssl x509 -noout -subject -in " + quote(p("rogue/ca/ca.pem")));
  EXPECT_EQ(ours.output, theirs.output);
}

TEST_F(Keys, KeysAreEcdsaP256AndCertificatesMatchTheirKeys) {
  for (const std::string id : {"ccu", "fl", "rr"}) {
    const auto text = run_shell("openssl x509 -noout -text -in " + quote(p(id + "/cert.pem")));
    ASSERT_EQ(text.status, 0);
    EXPECT_NE(text.output.find("prime256v1"), std::string::npos) << text.output;
    EXPECT_NE(text.output.find("ecdsa-with-SHA256"), std::string::npos);
    EXPECT_NE(text.output.find("CA:FALSE"), std::string::npos);
    const auto cert_pub = run_shell("openssl x509 -noout -pubkey -in " + quote(p(id + "/cert.pem")));
    const auto key_pub = run_shell("openssl pkey -pubout -in " + quote(p(id + "/key.pem")));
    EXPECT_EQ(cert_pub.output, key_pub.output) << id;
    struct stat st {};
    ASSERT_EQ(::stat(p(id + "/key.pem").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u) << id << ": private key must be readable by its owner only";
  }
  const auto ca = run_shell("openssl x509 -noout -text -in " + quote(p("ca/ca.pem")));
  EXPECT_NE(ca.output.find("CA:TRUE"), std::string::npos);
  EXPECT_NE(ca.output.find("prime256v1"), std::string::npos);
}

TEST_F(Keys, DocumentsAreSignedByTheCaOnlyAndCarryTheXml) {
  std::string text;
  ASSERT_TRUE(smime_ok(p("ca/ca.pem"), p("governance.p7s"), &text));
  EXPECT_EQ(text, read_text(p("governance.xml")));
  EXPECT_FALSE(smime_ok(p("rogue/ca/ca.pem"), p("governance.p7s")));
  for (const auto& id : bbw::security::identities()) {
    ASSERT_TRUE(smime_ok(p("ca/ca.pem"), p(id + "/permissions.p7s"), &text)) << id;
    EXPECT_EQ(text, read_text(p(id + "/permissions.xml"))) << id;
    EXPECT_FALSE(smime_ok(p("rogue/ca/ca.pem"), p(id + "/permissions.p7s"))) << id;
  }
  // The intruder's documents are signed by the rogue CA, not ours.
  EXPECT_FALSE(smime_ok(p("ca/ca.pem"), p("rogue/intruder/permissions.p7s")));
  EXPECT_TRUE(smime_ok(p("rogue/ca/ca.pem"), p("rogue/intruder/permissions.p7s")));
}

TEST_F(Keys, ATamperedDocumentNoLongerVerifies) {
  std::string doc = read_text(p("fl/permissions.p7s"));
  const std::string from = "<partition>corner_FL</partition>";
  const auto at = doc.find(from);
  ASSERT_NE(at, std::string::npos);
  doc.replace(at, from.size(), "<partition>corner_*_</partition>");  // same length, wider grant
  const std::string tampered = p("fl/tampered.p7s");
  {
    std::ofstream out(tampered, std::ios::binary);
    out << doc;
  }
  EXPECT_FALSE(smime_ok(p("ca/ca.pem"), tampered));
  std::filesystem::remove(tampered);
}

TEST_F(Keys, GovernanceProtectsEverything) {
  const std::string g = read_text(p("governance.xml"));
  for (const std::string want :
       {"<allow_unauthenticated_participants>false<", "<enable_join_access_control>true<",
        "<discovery_protection_kind>ENCRYPT<", "<liveliness_protection_kind>ENCRYPT<",
        "<enable_discovery_protection>true<", "<enable_liveliness_protection>true<",
        "<enable_read_access_control>true<", "<enable_write_access_control>true<",
        "<metadata_protection_kind>ENCRYPT<", "<data_protection_kind>ENCRYPT<", "<topic_expression>*<"}) {
    EXPECT_NE(g.find(want), std::string::npos) << want;
  }
}

// The <publish> block of a permissions document: topics and partitions.
struct Grant {
  std::string subject;
  std::string publish;
  std::string subscribe;
  std::string default_rule;
};

Grant parse_grant(const std::string& xml) {
  Grant g;
  std::smatch m;
  if (std::regex_search(xml, m, std::regex("<subject_name>([^<]*)</subject_name>"))) g.subject = m[1];
  if (std::regex_search(xml, m, std::regex("<publish>([\\s\\S]*?)</publish>"))) g.publish = m[1];
  if (std::regex_search(xml, m, std::regex("<subscribe>([\\s\\S]*?)</subscribe>"))) g.subscribe = m[1];
  if (std::regex_search(xml, m, std::regex("<default>([^<]*)</default>"))) g.default_rule = m[1];
  return g;
}

bool has_topic(const std::string& block, const char* topic) {
  return block.find(std::string("<topic>") + topic + "</topic>") != std::string::npos;
}

TEST_F(Keys, OnlyTheCcuMayCommandAndEachCornerWritesOnlyItsOwnPartition) {
  using namespace bbw::dds;
  const Grant ccu = parse_grant(read_text(p("ccu/permissions.xml")));
  EXPECT_EQ(ccu.default_rule, "DENY");
  EXPECT_TRUE(has_topic(ccu.publish, kCommandTopic));
  EXPECT_TRUE(has_topic(ccu.publish, kCalibrationTopic));
  EXPECT_FALSE(has_topic(ccu.publish, kMeasurementTopic));
  EXPECT_FALSE(has_topic(ccu.publish, kHealthTopic));
  EXPECT_TRUE(has_topic(ccu.subscribe, kMeasurementTopic));
  EXPECT_TRUE(has_topic(ccu.subscribe, kHealthTopic));
  EXPECT_NE(ccu.subscribe.find(std::string("<partition>") + bbw::security::kCornerPartitionPattern),
            std::string::npos);

  for (int corner = 0; corner < 4; ++corner) {
    const std::string id = bbw::security::corner_identity(corner);
    const Grant g = parse_grant(read_text(p(id + "/permissions.xml")));
    EXPECT_EQ(g.default_rule, "DENY") << id;
    EXPECT_TRUE(has_topic(g.publish, kMeasurementTopic)) << id;
    EXPECT_TRUE(has_topic(g.publish, kHealthTopic)) << id;
    EXPECT_FALSE(has_topic(g.publish, kCommandTopic)) << id;
    EXPECT_FALSE(has_topic(g.publish, kCalibrationTopic)) << id;
    EXPECT_NE(g.publish.find("<partition>" + bbw::security::corner_partition(corner) + "</partition>"),
              std::string::npos)
        << id;
    // Its partition in one run, corner_<C>.run_<id> (issue 17), is its only wildcard: it
    // matches no other corner's partition.
    const std::string run_grant = "<partition>" + bbw::security::corner_partition(corner) + ".run_*</partition>";
    std::string rest = g.publish;
    ASSERT_NE(rest.find(run_grant), std::string::npos) << id;
    rest.erase(rest.find(run_grant), run_grant.size());
    EXPECT_EQ(rest.find("*"), std::string::npos) << id << ": no other wildcard in a corner's publish grant";
    EXPECT_TRUE(has_topic(g.subscribe, kCommandTopic)) << id;
    EXPECT_TRUE(has_topic(g.subscribe, kCalibrationTopic)) << id;
  }
}

TEST_F(Keys, PermissionSubjectsAreTheCertificateSubjects) {
  for (const auto& id : bbw::security::identities()) {
    const auto subject = run_shell("openssl x509 -noout -subject -nameopt RFC2253 -in " + quote(p(id + "/cert.pem")));
    ASSERT_EQ(subject.status, 0);
    const Grant g = parse_grant(read_text(p(id + "/permissions.xml")));
    EXPECT_EQ("subject=" + g.subject + "\n", subject.output) << id;
  }
}

TEST_F(Keys, RerunKeepsKeysAndDocumentsAndRepairsAMissingIdentity) {
  const std::string ca = read_text(p("ca/ca.pem"));
  const std::string fl_key = read_text(p("fl/key.pem"));
  const std::string gov = read_text(p("governance.p7s"));
  const auto again = run_shell(quote(bbw::test::keys_script()) + " " + quote(keys_->dir().string()));
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_EQ(read_text(p("ca/ca.pem")), ca);
  EXPECT_EQ(read_text(p("fl/key.pem")), fl_key);
  EXPECT_EQ(read_text(p("governance.p7s")), gov) << "an unchanged document must not be re-signed";
  EXPECT_EQ(again.output.find("new "), std::string::npos) << again.output;

  // A deleted identity is re-created alone, still signed by the same CA.
  std::filesystem::remove(p("rr/cert.pem"));
  const auto repair = run_shell(quote(bbw::test::keys_script()) + " " + quote(keys_->dir().string()));
  ASSERT_EQ(repair.status, 0) << repair.output;
  EXPECT_EQ(read_text(p("ca/ca.pem")), ca);
  EXPECT_NE(repair.output.find("new identity bbw_rr"), std::string::npos) << repair.output;
  EXPECT_TRUE(verifies(p("ca/ca.pem"), p("rr/cert.pem")));
}

TEST(KeysCommand, ForceMakesANewCaAndErrorsAreExplained) {
  TempKeys keys;
  ASSERT_EQ(keys.status(), 0) << keys.output();
  const std::string ca = read_text(keys.path("ca/ca.pem"));
  const auto forced = run_shell(quote(bbw::test::keys_script()) + " " + quote(keys.dir().string()) + " --force");
  ASSERT_EQ(forced.status, 0) << forced.output;
  EXPECT_NE(read_text(keys.path("ca/ca.pem")), ca);
  EXPECT_EQ(run_shell("openssl verify -CAfile " + quote(keys.path("ca/ca.pem")) + " " + quote(keys.path("fl/cert.pem"))).status, 0);

  const auto no_dir = run_shell(quote(bbw::test::keys_script()));
  EXPECT_NE(no_dir.status, 0);
  EXPECT_NE(no_dir.output.find("usage: bbw keys DIR"), std::string::npos) << no_dir.output;
  const auto bad_opt = run_shell(quote(bbw::test::keys_script()) + " " + quote(keys.dir().string()) + " --frobnicate");
  EXPECT_NE(bad_opt.status, 0);
  EXPECT_NE(bad_opt.output.find("unknown option '--frobnicate'"), std::string::npos) << bad_opt.output;
  // A regular file where the directory should be.
  const auto file_dir = run_shell(quote(bbw::test::keys_script()) + " " + quote(keys.path("governance.xml")));
  EXPECT_NE(file_dir.status, 0);
  EXPECT_NE(file_dir.output.find("bbw keys: "), std::string::npos) << file_dir.output;
}

TEST_F(Keys, SecurityFilesAndPropertiesPointAtTheKeys) {
  const auto files = bbw::security::files_for(keys_->dir().string(), "fl");
  EXPECT_EQ(files.identity_cert, std::filesystem::canonical(p("fl/cert.pem")).string());
  EXPECT_EQ(files.permissions, std::filesystem::canonical(p("fl/permissions.p7s")).string());
  EXPECT_EQ(files.governance, std::filesystem::canonical(p("governance.p7s")).string());
  const auto props = bbw::security::participant_properties(files);
  auto find = [&](const std::string& key) -> std::string {
    for (const auto& [k, v] : props) {
      if (k == key) return v;
    }
    return "<missing>";
  };
  EXPECT_EQ(find("dds.sec.auth.plugin"), "builtin.PKI-DH");
  EXPECT_EQ(find("dds.sec.access.plugin"), "builtin.Access-Permissions");
  EXPECT_EQ(find("dds.sec.crypto.plugin"), "builtin.AES-GCM-GMAC");
  EXPECT_EQ(find("dds.sec.auth.builtin.PKI-DH.private_key"), "file://" + files.private_key);
  EXPECT_EQ(find("dds.sec.access.builtin.Access-Permissions.permissions"), "file://" + files.permissions);
  EXPECT_EQ(props.size(), 9u);
}

TEST(SecurityHelpers, RejectUnknownIdentitiesCornersAndMissingFiles) {
  using bbw::security::SecurityError;
  EXPECT_EQ(bbw::security::corner_identity("FL"), "fl");
  EXPECT_EQ(bbw::security::corner_identity("rr"), "rr");
  EXPECT_EQ(bbw::security::corner_identity(2), "rl");
  EXPECT_EQ(bbw::security::corner_partition(1), "corner_FR");
  EXPECT_EQ(bbw::security::corner_partition("rl"), "corner_RL");
  EXPECT_THROW(bbw::security::corner_identity("XX"), SecurityError);
  EXPECT_THROW(bbw::security::corner_partition(4), SecurityError);
  EXPECT_THROW(bbw::security::corner_partition(-1), SecurityError);
  EXPECT_THROW(bbw::security::files_for("/nonexistent", "intruder"), SecurityError);
  try {
    bbw::security::files_for("/nonexistent/keys", "ccu");
    FAIL() << "no throw";
  } catch (const SecurityError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/keys/ca/ca.pem"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("./bbw keys /nonexistent/keys"), std::string::npos) << e.what();
  }
}

}  // namespace
