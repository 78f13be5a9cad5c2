#include "sowing_robot/cli/options.h"

#include <algorithm>
#include <cstddef>

namespace sowing_robot::cli {

std::string parseOptions(int argc, const char* const* argv, const Parse& p, po::variables_map& vm,
                         std::vector<std::string>* order) {
  const std::string see = std::string(" (see ") + p.cmd + " --help)";
  try {
    // unix_style without guessing: "--fie" is an unknown option, not --field.
    const int style = po::command_line_style::unix_style ^ po::command_line_style::allow_guessing;
    po::command_line_parser parser(argc, argv);
    parser.options(p.options).positional(p.positional).style(style);
    if (!p.fixed_arity.empty())
      parser.extra_style_parser([&p](std::vector<std::string>& args) {
        std::vector<po::option> out;
        for (const auto& [name, arity] : p.fixed_arity) {
          if (args.empty() || args.front() != "--" + name) continue;
          const auto end = args.begin() + std::min<std::ptrdiff_t>(1 + arity, static_cast<std::ptrdiff_t>(args.size()));
          po::option o(name, std::vector<std::string>(args.begin() + 1, end));
          o.original_tokens.assign(args.begin(), end);
          args.erase(args.begin(), end);
          out.push_back(o);
          break;
        }
        return out;
      });
    const po::parsed_options parsed = parser.run();
    po::store(parsed, vm);
    po::notify(vm);
    if (order)
      for (const po::option& o : parsed.options) order->push_back(o.string_key);
  } catch (const po::unknown_option& e) {
    return "unknown option '" + e.get_option_name() + "'" + see;
  } catch (const po::invalid_command_line_syntax& e) {
    if (e.kind() == po::invalid_syntax::missing_parameter)
      return p.missing ? p.missing(e.get_option_name()) : e.get_option_name() + " needs a value" + see;
    return e.what() + see;
  } catch (const po::multiple_occurrences& e) {
    return e.get_option_name() + " given more than once" + see;
  } catch (const po::error& e) {
    return e.what() + see;
  }
  return "";
}

}  // namespace sowing_robot::cli
