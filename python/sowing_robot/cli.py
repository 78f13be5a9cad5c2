"""--help and unknown options for the package's Python commands, as for the C++ ones
(include/sowing_robot/cli/usage.h) and the bash ones (scripts/lib/cli.bash):

  --help / -h    the command's usage: its docstring (the description) and argparse's options, exit 0
  an unknown option: one line on stderr, exit 2:  <cmd>: unknown option '--x' (see <cmd> --help)

Needs nothing but the standard library, so a command can answer --help without a sourced workspace (the
scripts fall back on the source tree's python/ for this module)."""
import argparse
import sys


def _number(arg):
    try:
        float(arg)
        return True
    except ValueError:
        return False


class Parser(argparse.ArgumentParser):
    """argparse with the package's answer to an unknown option; `doc` (the command's docstring) is printed
    as written above the options."""

    def __init__(self, doc=None, **kwargs):
        kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(description=doc, **kwargs)

    def unknown(self, arg):
        what = "unknown option" if arg.startswith("-") else "unexpected argument"
        self.exit(2, "%s: %s '%s' (see %s --help)\n" % (self.prog, what, arg, self.prog))

    def parse_args(self, args=None, namespace=None):
        # Unknown options first: argparse would report a missing positional before them.
        args = sys.argv[1:] if args is None else list(args)
        for a in args:
            if a == "--":
                break
            if a.startswith("-") and a != "-" and not _number(a) and a.split("=", 1)[0] not in self._option_string_actions:
                self.unknown(a)
        return super().parse_args(args, namespace)

    def error(self, message):
        prefix = "unrecognized arguments: "
        if message.startswith(prefix):
            self.unknown(message[len(prefix):].split()[0])
        self.exit(2, "%s: error: %s (see %s --help)\n" % (self.prog, message, self.prog))
