// cncd-web's HTTP surface against the real daemon: login, what is served without it, and the
// program files with every kind of name that must not reach outside PROGRAM_DIR.
#include <fstream>

#include "web_fixture.hpp"

namespace cncd::test {
namespace {

std::vector<std::string> names_in(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST_F(WebTest, LoginSetsAStrictHttpOnlyCookie) {
  const auto reply = login("otto", password("otto"));
  ASSERT_EQ(reply.status, 200) << reply.body;
  EXPECT_EQ(reply.json()["user"], "otto");
  EXPECT_EQ(reply.json()["role"], "operator");
  const auto set = reply.header("set-cookie");
  EXPECT_TRUE(set.starts_with("cncd_session=")) << set;
  EXPECT_NE(set.find("HttpOnly"), std::string::npos) << set;
  EXPECT_NE(set.find("SameSite=Strict"), std::string::npos) << set;
  EXPECT_NE(set.find("Path=/"), std::string::npos) << set;
  EXPECT_EQ(set.find("Secure"), std::string::npos) << "no TLS here: " << set;
  const auto session =
      http_request(port_, "GET", "/api/session", "", {{"Cookie", set.substr(0, set.find(';'))}});
  ASSERT_EQ(session.status, 200);
  EXPECT_EQ(session.json()["role"], "operator");
  EXPECT_FALSE(session.json()["methods"].empty());
}

TEST_F(WebTest, WrongPasswordsAreRefusedThenRateLimited) {
  EXPECT_EQ(login("otto", "nope").status, 401);
  EXPECT_EQ(login("nobody", "nope").status, 401);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(login("otto", "nope").status, 401);
  // Five failures from this address: even the right password waits now.
  const auto limited = login("otto", password("otto"));
  EXPECT_EQ(limited.status, 429) << limited.body;
  EXPECT_GE(std::stoi(limited.header("retry-after")), 1);
}

TEST_F(WebTest, WithoutLoginOnlyTheLoginPage) {
  const auto root = http_request(port_, "GET", "/");
  EXPECT_EQ(root.status, 303);
  EXPECT_EQ(root.header("location"), "/login.html");
  EXPECT_EQ(http_request(port_, "GET", "/login.html").status, 200);
  EXPECT_EQ(http_request(port_, "GET", "/index.html").status, 303);
  EXPECT_EQ(http_request(port_, "GET", "/app.js").status, 401);
  EXPECT_EQ(http_request(port_, "GET", "/api/programs").status, 401);
  EXPECT_EQ(http_request(port_, "GET", "/api/session").status, 401);
  EXPECT_EQ(http_request(port_, "PUT", "/api/programs/a.ngc", "G0 X1\n").status, 401);
  EXPECT_EQ(
      http_request(port_, "GET", "/api/session", "", {{"Cookie", "cncd_session=forged"}}).status,
      401);
  EXPECT_EQ(http_request(port_, "GET", "/", "", {{"Authorization", "Bearer cncd_forged"}}).status,
            303);
  WsClient ws;
  EXPECT_EQ(ws.open(port_, {}), 401);
  EXPECT_TRUE(names_in(programs_).empty());
  // Logged in, the page.
  const auto page = http_request(port_, "GET", "/", "", {{"Cookie", cookie("olga")}});
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("cncd"), std::string::npos);
  EXPECT_EQ(page.header("content-type"), "text/html; charset=utf-8");
}

TEST_F(WebTest, UploadListDownloadRenameDelete) {
  const auto sam = cookie("sam");
  const std::string program = "G0 X1 Y2\nG1 X3 F100\nM2\n";
  const auto put = http_request(port_, "PUT", "/api/programs/part.ngc", program, {{"Cookie", sam}});
  ASSERT_EQ(put.status, 201) << put.body;
  EXPECT_EQ(put.json()["size"], program.size());
  EXPECT_EQ(slurp(programs_ / "part.ngc"), program);
  const auto list = http_request(port_, "GET", "/api/programs", "", {{"Cookie", sam}});
  ASSERT_EQ(list.status, 200);
  ASSERT_EQ(list.json().size(), 1u) << list.body;
  EXPECT_EQ(list.json()[0]["name"], "part.ngc");
  EXPECT_EQ(list.json()[0]["size"], program.size());
  const auto got = http_request(port_, "GET", "/api/programs/part.ngc", "", {{"Cookie", sam}});
  EXPECT_EQ(got.status, 200);
  EXPECT_EQ(got.body, program);

  auto ws_sam = ws("sam");
  EXPECT_TRUE(
      ws_sam->call("files.rename", {{"from", "part.ngc"}, {"to", "b.ngc"}}).contains("result"));
  EXPECT_EQ(names_in(programs_), std::vector<std::string>{"b.ngc"});
  const auto files = ws_sam->call("files.list");
  ASSERT_EQ(files["result"].size(), 1u) << files.dump();
  EXPECT_EQ(files["result"][0]["name"], "b.ngc");
  EXPECT_TRUE(ws_sam->call("files.delete", {{"name", "b.ngc"}}).contains("result"));
  EXPECT_TRUE(names_in(programs_).empty());
}

TEST_F(WebTest, NamesOutsideTheProgramDirectoryAreRefused) {
  const auto sam = cookie("sam");
  std::ofstream(outside_ / "victim.ngc") << "G0 X0\n";
  std::filesystem::create_symlink(outside_ / "victim.ngc", programs_ / "link.ngc");
  for (const std::string& target : std::vector<std::string>{
           "/api/programs/../x", "/api/programs/%2e%2e%2fx", "/api/programs/%2E%2E%2Fx",
           "/api/programs//abs", "/api/programs/" + outside_.string(), "/api/programs/a%00b",
           "/api/programs/%00", "/api/programs/..", "/api/programs/.hidden",
           "/api/programs/sub%2fx", "/api/programs/"}) {
    const auto put = http_request(port_, "PUT", target, "G0 X9\n", {{"Cookie", sam}});
    EXPECT_TRUE(put.status == 400 || put.status == 404) << target << ": " << put.status << put.body;
    const auto get = http_request(port_, "GET", target, "", {{"Cookie", sam}});
    EXPECT_GE(get.status, 400) << target << ": " << get.body;
  }
  // The symlink out: not followed for reading, nor for opening.
  EXPECT_EQ(http_request(port_, "GET", "/api/programs/link.ngc", "", {{"Cookie", sam}}).status,
            403);
  auto ws_sam = ws("sam");
  EXPECT_NE(code_of(ws_sam->call("program.open", {{"path", "link.ngc"}})), 0);
  EXPECT_NE(code_of(ws_sam->call("files.open", {{"name", "link.ngc"}})), 0);
  EXPECT_NE(code_of(ws_sam->call("program.open", {{"path", (outside_ / "victim.ngc").string()}})),
            0);
  EXPECT_NE(code_of(ws_sam->call("program.open", {{"path", "../outside/victim.ngc"}})), 0);
  EXPECT_NE(code_of(ws_sam->call("files.rename", {{"from", "link.ngc"}, {"to", "../x"}})), 0);
  // Writing to the symlink's name replaces the link, never its target.
  EXPECT_EQ(
      http_request(port_, "PUT", "/api/programs/link.ngc", "G0 X7\n", {{"Cookie", sam}}).status,
      201);
  EXPECT_EQ(slurp(outside_ / "victim.ngc"), "G0 X0\n");
  EXPECT_EQ(names_in(outside_), std::vector<std::string>{"victim.ngc"});
  EXPECT_EQ(names_in(programs_), std::vector<std::string>{"link.ngc"});
  EXPECT_FALSE(std::filesystem::is_symlink(programs_ / "link.ngc"));
  EXPECT_FALSE(std::filesystem::exists(dir_.path() / "x"));
}

TEST_F(WebTest, TooLargeUploadIs413AndLeavesNoFile) {
  const auto sam = cookie("sam");
  const std::string big((1 << 20) + 1, 'G');  // MAX_UPLOAD_MB = 1
  const auto put = http_request(port_, "PUT", "/api/programs/big.ngc", big, {{"Cookie", sam}});
  EXPECT_EQ(put.status, 413) << put.body;
  // Of unknown length (chunked): stopped while reading, at the limit. Either the 413 arrives
  // or the connection is cut while the rest is still being sent.
  const auto chunked = http_request(port_, "PUT", "/api/programs/big.ngc", big,
                                    {{"Cookie", sam}, {"Transfer-Encoding", "chunked"}});
  EXPECT_TRUE(chunked.status == 413 || chunked.status == 0) << chunked.status;
  EXPECT_TRUE(names_in(programs_).empty());
  const std::string fits(1 << 20, ';');
  EXPECT_EQ(http_request(port_, "PUT", "/api/programs/fits.ngc", fits, {{"Cookie", sam}}).status,
            201);
  EXPECT_EQ(names_in(programs_), std::vector<std::string>{"fits.ngc"});
}

TEST_F(WebTest, WrongOriginAndObserversCannotUpload) {
  const auto sam = cookie("sam");
  EXPECT_EQ(http_request(port_, "PUT", "/api/programs/a.ngc", "G0 X1\n",
                         {{"Cookie", sam}, {"Origin", "http://evil.example"}})
                .status,
            403);
  EXPECT_EQ(
      http_request(port_, "PUT", "/api/programs/a.ngc", "G0 X1\n", {{"Cookie", cookie("olga")}})
          .status,
      403);
  EXPECT_EQ(http_request(port_, "PUT", "/api/programs/a.ngc", "G0 X1\n",
                         {{"Cookie", cookie("otto")}, {"Origin", origin()}})
                .status,
            403);
  EXPECT_TRUE(names_in(programs_).empty());
  EXPECT_EQ(http_request(port_, "PUT", "/api/programs/a.ngc", "G0 X1\n",
                         {{"Cookie", sam}, {"Origin", origin()}})
                .status,
            201);
}

TEST_F(WebTest, ApiKeyUploadsWithoutCookie) {
  BackgroundCommand add({CNCD_WEB_BINARY, "--ini", ini_.string(), "key", "add", "sam"});
  const auto result = add.wait();
  ASSERT_EQ(result.exit_status, 0) << result.err;
  const auto at = result.out.find("cncd_");
  ASSERT_NE(at, std::string::npos) << result.out;
  const std::string key = result.out.substr(at, 48);
  EXPECT_EQ(http_request(port_, "PUT", "/api/programs/cam.ngc", "G0 X1\n",
                         {{"Authorization", "Bearer " + key}})
                .status,
            201);
  EXPECT_EQ(http_request(port_, "PUT", "/api/programs/cam2.ngc", "G0 X1\n",
                         {{"Authorization", "Bearer " + key + "x"}})
                .status,
            401);
  EXPECT_EQ(names_in(programs_), std::vector<std::string>{"cam.ngc"});
}

}  // namespace
}  // namespace cncd::test
