# --help and unknown options for the package's bash commands, alike for every command; sourced, not run.
# A command's usage is its header comment (line 2 up to the first line that is not a comment): --help / -h
# prints it to stdout and exits 0 before any work; an unknown option is one line on stderr and exit 2.
# The command sets ROOT (the repo) before sourcing this file.
CLI_NAME="$(realpath --relative-to="$ROOT" "$0" 2>/dev/null || basename "$0")"  # scripts/run, scripts/dev/bench

cli_help() {
  sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"
  exit 0
}

cli_unknown() {  # cli_unknown ARG
  if [[ "$1" == -* ]]; then
    echo "$CLI_NAME: unknown option '$1' (see $CLI_NAME --help)" >&2
  else
    echo "$CLI_NAME: unexpected argument '$1' (see $CLI_NAME --help)" >&2
  fi
  exit 2
}

cli_no_arguments() {  # cli_no_arguments "$@": for a command that takes none (its settings are variables)
  local a
  for a in "$@"; do case "$a" in -h|--help) cli_help ;; esac; done
  [ $# -eq 0 ] || cli_unknown "$1"
}
