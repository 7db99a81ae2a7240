#include "app/options/help_sections.h"

#include <algorithm>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace waxwork {

namespace {

// CLI11 prints option groups in the order their first option was added; the options shared by several
// commands are added by common helpers in an order that suits none of them. This formatter prints the
// ungrouped options first, then the sections in the order given, and the example after the description.
class SectionFormatter : public CLI::Formatter {
public:
    SectionFormatter(std::vector<std::string> order, std::string example)
        : order_(std::move(order)), example_(std::move(example)) {}

    std::string make_description(const CLI::App* app) const override {
        std::string text = CLI::Formatter::make_description(app);
        if (!example_.empty()) text += "Example:\n  " + example_ + "\n\n";
        return text;
    }

    // CLI11's make_help with ordered_groups for its make_groups (not virtual in CLI11 2.1).
    std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override {
        if (mode == CLI::AppFormatMode::Sub) return make_expanded(app);
        std::ostringstream out;
        out << make_description(app) << make_usage(app, std::move(name)) << make_positionals(app)
            << ordered_groups(app, mode) << make_subcommands(app, mode) << '\n'
            << make_footer(app);
        return out.str();
    }

private:
    std::string ordered_groups(const CLI::App* app, CLI::AppFormatMode mode) const {
        std::vector<std::string> groups = app->get_groups();
        const auto rank = [&](const std::string& g) {
            const auto it = std::find(order_.begin(), order_.end(), g);
            return it == order_.end() ? -1 : static_cast<int>(it - order_.begin());
        };
        std::stable_sort(groups.begin(), groups.end(), [&](const std::string& a, const std::string& b) { return rank(a) < rank(b); });
        std::ostringstream out;
        for (const std::string& group : groups) {
            const std::vector<const CLI::Option*> options = app->get_options([&](const CLI::Option* o) {
                return o->get_group() == group && o->nonpositional() &&
                       (mode != CLI::AppFormatMode::Sub || (app->get_help_ptr() != o && app->get_help_all_ptr() != o));
            });
            if (group.empty() || options.empty()) continue;
            out << make_group(group, false, options);
        }
        return out.str();
    }

    std::vector<std::string> order_;
    std::string example_;
};

}  // namespace

void organise_help(CLI::App& command, const std::string& example, const std::vector<HelpSection>& sections) {
    std::vector<std::string> order;
    for (const HelpSection& section : sections) {
        order.push_back(section.title);
        for (const std::string& name : section.options) {
            CLI::Option* option = command.get_option_no_throw(name);
            if (!option) throw std::logic_error("help: " + command.get_name() + " has no option " + name);
            option->group(section.title);
        }
    }
    command.formatter(std::make_shared<SectionFormatter>(std::move(order), example));
}

}  // namespace waxwork
