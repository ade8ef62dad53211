#include "admin_entry.hpp"

#include <unistd.h>

#include <iostream>

#include <spdlog/spdlog.h>

#include "cncd/web/admin_cli.hpp"

namespace cncd::web {

int run_admin(const std::vector<std::string>& args, const config::WebConfig& web) {
  if (!is_admin_command(args)) {
    std::cerr << "cncd-web: unknown command '" << args.front() << "'\n" << admin_usage();
    return 2;
  }
  AdminOptions options;
  options.input_fd = isatty(STDIN_FILENO) ? STDIN_FILENO : -1;
  return run_admin_command(args, web, std::cin, std::cout, std::cerr, options);
}

std::string prepare(App& app) {
  if (!app.programs.ok()) return "[WEB] PROGRAM_DIR: " + app.programs.open_error();
  if (auto problem = app.users.load(); !problem.empty()) return problem;
  if (app.users.users().empty()) {
    spdlog::warn(
        "no users in {}: nobody can log in; add one with cncd-web --ini {} user add "
        "NAME --role admin",
        app.web.users_file.string(), app.machine.path.string());
  }
  if (!std::filesystem::exists(app.www_dir / "index.html"))
    spdlog::warn("no index.html in {}: the page is missing (--www DIR)", app.www_dir.string());
  if (app.web.tls_cert.empty() != app.web.tls_key.empty())
    return "[WEB] TLS_CERT and TLS_KEY go together";
  if (!app.web.tls_cert.empty()) {
    namespace ssl = boost::asio::ssl;
    try {
      auto& tls = app.tls.emplace(ssl::context::tls_server);
      tls.set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 |
                      ssl::context::no_sslv3 | ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1 |
                      ssl::context::single_dh_use);
      tls.use_certificate_chain_file(app.web.tls_cert.string());
      tls.use_private_key_file(app.web.tls_key.string(), ssl::context::pem);
    } catch (const boost::system::system_error& e) {
      app.tls.reset();
      return "[WEB] TLS_CERT " + app.web.tls_cert.string() + " / TLS_KEY " +
             app.web.tls_key.string() + ": " + e.what();
    }
  }
  return "";
}

}  // namespace cncd::web
