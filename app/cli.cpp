#include "app/cli.h"

#include "app/commands.h"
#include "base/error.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <ostream>
#include <string>

namespace waxwork {
namespace {

// An error message as one line of text: messages quote what they could not read, which in a binary
// file is raw bytes (terminal control codes, invalid UTF-8); every byte outside printable ASCII is
// shown as \xNN.
std::string printable(const std::string& message) {
    std::string out;
    out.reserve(message.size());
    for (const char c : message) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte >= 0x20 && byte < 0x7f) {
            out += c;
        } else {
            char escaped[5];
            std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
            out += escaped;
        }
    }
    return out;
}

// CLI11 reads an empty value ("--relax ''") as the option's default instead of refusing it, so a
// script that lost a variable would silently run with defaults. No option of ours means anything by
// empty text: every option that takes a value, in every command, refuses it.
void refuse_empty_values(CLI::App& app) {
    const CLI::Validator non_empty(
        [](std::string& text) { return text.empty() ? std::string("an empty value is not allowed") : std::string(); },
        "", "non-empty");
    for (CLI::Option* option : app.get_options())
        if (option->get_type_size_max() > 0) option->check(non_empty);
    for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) refuse_empty_values(*command);
}

ProgramArguments& arguments() {
    static ProgramArguments kept;
    return kept;
}

// A process that mpirun started with a rank other than 0 (Open MPI's, MPICH's or PMIx's variable).
bool is_secondary_mpi_rank() {
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
        if (const char* rank = std::getenv(name)) return std::string(rank) != "0";
    return false;
}

// Where an error message goes: stderr, or nowhere on a secondary rank (rank 0 prints it).
std::ostream& error_stream() {
    static std::ostream discard(nullptr);
    return is_secondary_mpi_rank() ? discard : std::cerr;
}

}  // namespace

ProgramArguments program_arguments() { return arguments(); }

int run_cli(int argc, char** argv) {
    arguments() = {argc, argv};
    CLI::App app{"Waxwork: carve, fracture and paint translucent solids with live subsurface light.", "waxwork"};
    app.set_version_flag("--version", "waxwork 0.1.0");
    app.require_subcommand(1);
    app.failure_message([](const CLI::App*, const CLI::Error& e) { return std::string("waxwork: ") + e.what() + "\n"; });
    register_commands(app);
    refuse_empty_values(app);
    // CLI11 reports an unknown first word as a missing subcommand; name it instead.
    const auto is_command = [&app](const char* word) {
        try {
            return app.get_subcommand(word) != nullptr;
        } catch (const CLI::OptionNotFound&) {
            return false;
        }
    };
    if (argc > 1 && argv[1][0] != '-' && !is_command(argv[1])) {
        error_stream() << "waxwork: unknown command '" << argv[1] << "' (see waxwork --help)\n";
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        error_stream() << "waxwork: " << e.what() << " (see --help)\n";
        return 2;
    } catch (const Error& e) {
        error_stream() << "waxwork: " << printable(e.what()) << "\n";
        return 1;
    } catch (const std::exception& e) {
        error_stream() << "waxwork: internal error: " << printable(e.what()) << "\n";
        return 1;
    }
    return 0;
}

}  // namespace waxwork
