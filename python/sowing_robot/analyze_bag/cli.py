"""Command line of analyze_bag: arguments, the run, one-line errors and exit codes."""
import math
import os
import sys

from sowing_robot.analyze_bag.bag import BagError, _one_line, load_bag
from sowing_robot.analyze_bag.csv_export import write_csv
from sowing_robot.analyze_bag.metrics import metrics_table, thesis_runs, write_yaml
from sowing_robot.analyze_bag.plots import write_plots
from sowing_robot.analyze_bag.report import gaps, summary
from sowing_robot.cli import Parser

EXIT_OK, EXIT_INTERNAL, EXIT_USAGE, EXIT_BAD_BAG = 0, 1, 2, 3
PROG = "analyze_bag"


class UsageError(Exception):
    pass


class _Parser(Parser):
    """An unknown option is refused by Parser (one line, exit 2); other usage errors become UsageError."""

    def error(self, message):
        if message.startswith("unrecognized arguments: "):
            super().error(message)
        raise UsageError(message)


def parse_args(argv):
    p = _Parser("Tracking metrics (thesis Tables 5.5/5.6) and figures of sowing_robot bags.", prog=PROG)
    p.add_argument("bags", nargs="+", metavar="BAG",
                   help="bag files recorded by sim.launch record:=full (or lean: what it can)")
    p.add_argument("--labels", help="comma-separated column labels, one per bag (default: controller mode)")
    p.add_argument("--plots", metavar="DIR", help="directory for the PNG figures (default: next to the first bag)")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    p.add_argument("--markdown", metavar="FILE", help="also write the table and the summaries to FILE")
    p.add_argument("--yaml", metavar="FILE",
                   help="also write the metrics at full precision, in run_monitor's metrics_output format")
    p.add_argument("--csv", metavar="DIR",
                   help="also write one CSV per topic and bag (time, stamp_ns, fields) into DIR, for pandas")
    p.add_argument("--thesis", action="store_true", help="add the thesis's Table 5.5/5.6 values as columns")
    p.add_argument("--until", type=float, metavar="T",
                   help="only samples with stamp <= T [s] (run_monitor's duration), default all")
    args = p.parse_args(argv)
    if args.labels is not None:
        args.labels = [s.strip() for s in args.labels.split(",")]
        if len(args.labels) != len(args.bags) or not all(args.labels):
            raise UsageError("--labels needs %d non-empty comma-separated label(s), one per bag" % len(args.bags))
    if args.until is not None and not (math.isfinite(args.until) and args.until > 0.0):
        raise UsageError("--until must be a positive number of seconds")
    return args


def default_labels(datas):
    labels = []
    for d in datas:
        labels.append(d.mode() or os.path.splitext(os.path.basename(d.path))[0])
    for i, lab in enumerate(labels):
        if labels.count(lab) > 1:
            labels[i] = "%s (%s)" % (lab, os.path.splitext(os.path.basename(datas[i].path))[0])
    for i, lab in enumerate(labels):  # still equal (same file names in other directories): number them
        if labels.count(lab) > 1:
            labels[i] = "%s #%d" % (lab, i + 1)
    return labels


def load_bags(paths):
    """load_bag of each path, two at a time: the C++ reader releases the GIL (110 s of the default field: 1.5 s
    a bag). The first failing bag (in argument order) raises its BagError."""
    if len(paths) == 1:
        return [load_bag(paths[0])]
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=min(2, os.cpu_count() or 1)) as pool:
        futures = [pool.submit(load_bag, p) for p in paths]
        return [f.result() for f in futures]


def unique_stems(stems):
    """File-name stems, numbered where two bags share one (same name in other directories)."""
    return [s if stems.count(s) == 1 else "%s_%d" % (s, i + 1) for i, s in enumerate(stems)]


def run(argv):
    args = parse_args(argv)
    datas = load_bags(args.bags)
    runs = [d.metrics(args.until) for d in datas]
    labels = args.labels or default_labels(datas)
    for d, lab in zip(datas, labels):
        d.label = lab
    names, cols = list(labels), list(runs)
    if args.thesis:
        tn, tr = thesis_runs()
        names += tn
        cols += tr
    table = metrics_table(names, cols)
    summaries = [summary(d, args.until) for d in datas]
    print(table)
    print("\n\n".join(summaries))
    for d in datas:
        if d.truth_from_odom():
            sys.stderr.write("%s: warning: %s: no /ground_truth (a bag recorded before the sensors were modelled): the robot's path "
                             "and velocities are read from /odom, which was the true state then\n" % (PROG, d.path))
        for note in d.lean_notes():
            sys.stderr.write("%s: note: %s: %s\n" % (PROG, d.path, note))
        missing, ngaps = gaps(d.get("/tracking_error").stamps)
        if ngaps:
            sys.stderr.write("%s: warning: %s: %d /tracking_error samples missing in %d gap(s): the recorder dropped "
                             "messages, so these metrics can differ from run_monitor's\n" % (PROG, d.path, missing, ngaps))
    if args.yaml:
        try:
            write_yaml(args.yaml, labels, runs)
        except OSError as e:
            raise UsageError("cannot write --yaml %s: %s" % (args.yaml, e.strerror or e))
    if args.markdown:
        try:
            with open(args.markdown, "w") as f:
                f.write(table + "\n" + "\n\n".join(summaries) + "\n")
        except OSError as e:
            raise UsageError("cannot write --markdown %s: %s" % (args.markdown, e.strerror or e))
    stems = [os.path.splitext(os.path.basename(p))[0] for p in args.bags]
    if args.csv:
        try:
            written = write_csv(datas, args.csv, unique_stems(stems))
        except OSError as e:
            raise UsageError("cannot write --csv %s: %s" % (args.csv, e.strerror or e))
        print("\ncsv: " + " ".join(written))
    if not args.no_plots:
        out_dir = args.plots or (os.path.dirname(os.path.abspath(args.bags[0])))
        prefix = "_vs_".join(stems) if len(stems) <= 3 else stems[0] + "_and_%d_more" % (len(stems) - 1)
        try:
            written = write_plots(datas, out_dir, prefix)
        except OSError as e:
            raise UsageError("cannot write the plots in %s: %s" % (out_dir, e.strerror or e))
        print("\nplots: " + " ".join(written))
    return EXIT_OK


def main(argv=None):
    if argv is None:
        argv = [a for a in sys.argv[1:] if not (a.startswith("__") and ":=" in a)]  # roslaunch remaps
    try:
        return run(argv)
    except UsageError as e:
        sys.stderr.write("%s: error: %s (see %s --help)\n" % (PROG, e, PROG))
        return EXIT_USAGE
    except BagError as e:
        sys.stderr.write("%s: error: %s\n" % (PROG, e))
        return EXIT_BAD_BAG
    except ImportError as e:
        sys.stderr.write("%s: error: %s: run it with the system python3 of ROS (/usr/bin/python3) after sourcing "
                         "devel/setup.bash\n" % (PROG, _one_line(e)))
        return EXIT_INTERNAL
    except BrokenPipeError:  # e.g. `analyze_bag x.bag | head`: stop quietly
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_INTERNAL
    except KeyboardInterrupt:
        sys.stderr.write("%s: interrupted\n" % PROG)
        return 130
    except Exception as e:  # never a traceback for the user; the type says where to look
        sys.stderr.write("%s: internal error (%s): %s\n" % (PROG, type(e).__name__, _one_line(e)))
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
