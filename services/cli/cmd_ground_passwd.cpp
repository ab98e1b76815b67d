// tetra ground passwd — adds an operator account to the ground station's accounts file, or changes
// its password or role (docs/ground.md, "Accounts"). The password is read from the terminal without
// echo (twice), or with --password-stdin as the first line of standard input (scripts).

#include <termios.h>
#include <unistd.h>

#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/ground/operators.hpp"

namespace tetra::cli {

namespace {

//! One line of standard input, read no further than one character past kMaxPasswordBytes (an endless
//! input without a newline ends there; hash_password refuses what is too long).
std::string password_line() {
  std::string line;
  char c = 0;
  while (line.size() <= ground::kMaxPasswordBytes && std::cin.get(c) && c != '\n') line += c;
  return line;
}

//! One line from the terminal with echo off.
std::string ask_hidden(const std::string& prompt) {
  std::cerr << prompt << std::flush;
  termios old{};
  const bool tty = ::tcgetattr(STDIN_FILENO, &old) == 0;
  if (tty) {
    termios quiet = old;
    quiet.c_lflag &= ~static_cast<tcflag_t>(ECHO);
    ::tcsetattr(STDIN_FILENO, TCSANOW, &quiet);
  }
  const std::string line = password_line();
  if (tty) ::tcsetattr(STDIN_FILENO, TCSANOW, &old);
  std::cerr << '\n';
  return line;
}

}  // namespace

int cmd_ground_passwd(int argc, char** argv) {
  CLI::App app{"Adds an operator account of tetra ground, or sets its password or role.", "ground passwd"};
  std::string user;
  std::string users_path;
  std::string role_name = "viewer";
  bool from_stdin = false;
  app.add_option("user", user,
                 "the operator's id (1 to 31 of A-Z a-z 0-9 . _ -); one starting with - goes after --, which "
                 "ends the options: ground passwd --users FILE -- -x")
      ->required();
  app.add_option("--users", users_path, "the accounts file (created when absent, mode 0600)")->required();
  app.add_option("--role", role_name, "viewer (sees) or commander (sees and commands)")
      ->check(CLI::IsMember({"viewer", "commander"}))
      ->capture_default_str();
  app.add_flag("--password-stdin", from_stdin, "read the password from the first line of standard input");
  if (auto exit = parse(app, argc, argv)) return *exit;
  if (auto s = ground::valid_user_name(user); !s) return report("ground passwd", s.error());

  std::string password;
  if (from_stdin || !::isatty(STDIN_FILENO)) {
    if (!from_stdin)
      return report("ground passwd", bad_input("standard input is not a terminal: --password-stdin"));
    password = password_line();
  } else {
    password = ask_hidden("password for " + user + ": ");
    if (ask_hidden("again: ") != password)
      return report("ground passwd", bad_input("the two passwords differ"));
  }
  auto taken = ground::password_of_line(password);
  if (!taken) return report("ground passwd", taken.error());
  auto hash = ground::hash_password(*taken);
  if (!hash) return report("ground passwd", hash.error());
  const ground::Account account{user, *ground::role_named(role_name), *hash};
  if (auto s = ground::set_account(users_path, account); !s) return report("ground passwd", s.error());
  std::cout << "tetra ground passwd: " << user << " (" << role_name << ") in " << users_path << "\n";
  return kExitOk;
}

}  // namespace tetra::cli
