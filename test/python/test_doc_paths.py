"""Every path the README, docs/ and results/ name exists in the repository: backticked repo paths (`src/...`,
`config/...`, ...) and relative Markdown link targets. A renamed header, a moved doc or a figure no longer
generated then fails here, naming the file and line that still cite it. Plain text only: no build, no ROS."""
import glob
import os
import re

import pytest

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

# A backticked path is repo-relative when it starts with one of the package's top-level directories.
ROOTS = ("include/", "src/", "test/", "scripts/", "config/", "launch/", "docs/", "results/", "urdf/", "rviz/",
         "msg/", "cfg/", "benchmarks/", "python/")
# Globs and placeholders name no one file: `config/tuned/<pair>.yaml`, `results/*.png`, `$(rospack find ...)`.
PLACEHOLDER = ("*", "<", "{", "...", "$")

FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
LINE_SUFFIX = re.compile(r":\d+(-\d+)?$")


def documents():
    """README.md, docs/*.md and results/**/*.md, repo-relative."""
    found = ["README.md"] + sorted(glob.glob(os.path.join(REPO, "docs", "*.md")))
    found += sorted(glob.glob(os.path.join(REPO, "results", "**", "*.md"), recursive=True))
    return [os.path.relpath(os.path.join(REPO, f), REPO) for f in found]


def clean(path):
    """The path without its #anchor, ?query, :line suffix, a possessive 's (`config/robot.yaml's`) and the
    punctuation that closes a sentence."""
    path = path.split("#", 1)[0].split("?", 1)[0]
    path = path.rstrip(".,;:)")
    if path.endswith("'s"):
        path = path[:-2]
    return LINE_SUFFIX.sub("", path)


def cited_paths(text, doc_dir=""):
    """(line number, as written, repo-relative path) for every path the Markdown text names.

    Backticked spans outside fenced code blocks count when they start with one of ROOTS (a command's
    arguments included: `benchmark --profile config/profiles/field.yaml`); links count when relative (not
    http:, mailto:, nor an anchor in the same page) and resolve against doc_dir, the document's directory."""
    out = []
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if fenced:
            continue
        for match in LINK.finditer(line):
            target = match.group(1)
            if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target) or target.startswith("#"):
                continue
            if any(p in target for p in PLACEHOLDER):
                continue
            path = clean(target)
            if path:
                out.append((number, target, os.path.normpath(os.path.join(doc_dir, path))))
        without_links = LINK.sub("", line)
        for match in CODE_SPAN.finditer(without_links):
            for token in match.group(2).split():
                token = token.strip("'\"(")
                if not token.startswith(ROOTS) or any(p in token for p in PLACEHOLDER):
                    continue
                path = clean(token)
                if path:
                    out.append((number, token, os.path.normpath(path)))
    return out


def missing_paths(text, doc_dir="", root=REPO):
    """The cited paths that do not exist under root, as 'line N: as written'."""
    return ["line %d: %s" % (number, written) for number, written, path in cited_paths(text, doc_dir)
            if not os.path.exists(os.path.join(root, path))]


@pytest.mark.parametrize("doc", documents())
def test_every_path_a_document_names_exists(doc):
    with open(os.path.join(REPO, doc), encoding="utf-8") as f:
        text = f.read()
    missing = missing_paths(text, os.path.dirname(doc))
    assert not missing, "%s names paths that do not exist:\n  %s" % (doc, "\n  ".join(missing))


def test_the_scanner_reports_a_missing_path(tmp_path):
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "there.cpp").write_text("")
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "guide.md").write_text("")
    text = "\n".join([
        "Code: `src/there.cpp:12` and `src/does_not_exist.cpp`; [the guide](guide.md#setup), [gone](gone.md).",
        "A glob `src/*.cpp`, a placeholder `config/tuned/<pair>.yaml`, a site [x](https://example.org/a.md).",
        "```",
        "rosrun sowing_robot run --output src/written_by_the_command.cpp",
        "```",
        "Run `rosrun sowing_robot benchmark --profile src/missing_too.yaml`.",
    ])
    missing = missing_paths(text, "docs", root=str(tmp_path))
    assert missing == ["line 1: gone.md", "line 1: src/does_not_exist.cpp", "line 6: src/missing_too.yaml"]
