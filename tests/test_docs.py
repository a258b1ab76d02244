"""The documentation site (``mkdocs.yml``, ``docs/``) and the README cannot
drift from the code.

* The site builds with ``mkdocs build --strict``: a broken link or anchor, a
  missing image, a page outside ``nav`` or an API reference that does not
  resolve fails :func:`test_site_builds_strictly`. This test is CI's build of
  the site: ``.ci/run`` installs ``.[dev]``, which includes the ``docs``
  extra, and runs the default suite, so it needs no step of its own. Without
  the extra the test skips with the reason (a failure under ``CI=true``,
  ``tests/conftest.py``).
* The ``python`` blocks of the pages run, each in a fresh process in an empty
  folder (:func:`test_python_block_runs`), and every one compiles. A block
  is run unless the line before it is an HTML comment
  ``<!-- not run: REASON -->`` (compiled only) or ``<!-- slow: REASON -->``
  (run under ``-m slow``); ``<!-- snippet: NAME -->`` names a block whose
  output :data:`CHECKS` also checks (the Library example).
* Every ``python -m ignjax...`` (or ``ignjax-build``) command in the ``bash``
  blocks of the pages and of the README parses with that command's own
  argument parser, without running it; the sweep's and the trainer's
  ``--config`` / ``--set`` settings and the evaluation's agents and ``--set``
  items are checked as those commands check them before any work.
* The README is the front page: at most about 200 lines, the two commands CI
  runs first, every relative link and image present.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import importlib.util
import io
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
README_MAX_LINES = 200
FIRST_BLOCK = ['pip install -e . && python -m ignjax.sweep', 'pip install -e ".[dev]" && python -m pytest']
"""The README's first code block, byte for byte: ``.ci/run`` runs its second line."""


def pages() -> list[Path]:
    """Every Markdown page of the site (``docs/_ext`` holds code, not pages)."""
    return sorted(p for p in DOCS.rglob("*.md") if "_ext" not in p.relative_to(DOCS).parts)


# ---------------------------------------------------------------------------
# code blocks and their markers
# ---------------------------------------------------------------------------

FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>`{3,}|~{3,})[ \t]*(?P<info>[^`]*)$")
MARKER = re.compile(r"^\s*<!--\s*(?P<kind>not run|slow|snippet)\s*:\s*(?P<text>.*?)\s*-->\s*$")


@dataclass(frozen=True)
class Block:
    path: Path
    line: int  # 1-based line of the opening fence
    end: int  # 1-based line of the closing fence
    lang: str
    code: str
    marker: str | None = None  # "not run", "slow", "snippet" or None
    marker_text: str = ""

    @property
    def id(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def code_blocks(path: Path, text: str | None = None) -> list[Block]:
    """The fenced code blocks of a Markdown file (``text``, else read from ``path``; also indented blocks, inside
    list items), each with the marker comment on the line before it, if any."""
    lines = (path.read_text() if text is None else text).splitlines()
    out, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence = m["indent"], m["fence"]
        lang = (m["info"].split() or [""])[0].lower()
        close = re.compile(rf"^[ \t]*{re.escape(fence[0])}{{{len(fence)},}}[ \t]*$")
        j, body = i + 1, []
        while j < len(lines) and not close.match(lines[j]):
            body.append(lines[j][len(indent):] if lines[j].startswith(indent) else lines[j].lstrip())
            j += 1
        assert j < len(lines), f"{path.relative_to(ROOT)}:{i + 1}: a code block that is never closed"
        k = i - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        mk = MARKER.match(lines[k]) if k >= 0 else None
        out.append(Block(path, i + 1, j + 1, lang, "\n".join(body) + "\n", mk["kind"] if mk else None,
                         mk["text"] if mk else ""))
        i = j + 1
    return out


def python_blocks() -> list[Block]:
    return [b for p in [*pages(), README] for b in code_blocks(p) if b.lang in ("python", "py")]


def test_markers_give_a_reason_and_sit_on_python_blocks():
    for path in [*pages(), README]:
        text = path.read_text()
        for m in re.finditer(r"<!--\s*(not run|slow|snippet)\b(.*?)-->", text, re.S):
            assert MARKER.match(m.group(0)) and m.group(2).strip(" :"), \
                f"{path.relative_to(ROOT)}: {m.group(0)!r}: write <!-- {m.group(1)}: REASON --> on one line"
    marked = {(b.path, b.marker) for p in [*pages(), README] for b in code_blocks(p) if b.marker}
    assert all(b.lang in ("python", "py") for p in [*pages(), README] for b in code_blocks(p) if b.marker), marked


def test_every_python_block_compiles():
    blocks = python_blocks()
    assert len(blocks) >= 3
    for b in blocks:
        compile(b.code, b.id, "exec")


# ---------------------------------------------------------------------------
# running the python blocks
# ---------------------------------------------------------------------------


def _check_library(proc: subprocess.CompletedProcess, folder: Path) -> None:
    """The Library example of the Getting-started page: a Table-1 text table of
    ``eig`` and the WSR range over 1,000 cost vectors, from the files it wrote."""
    lines = proc.stdout.splitlines()
    assert lines[0].split()[:2] == ["Agent", "Easy"] and lines[1].split()[0] == "eig", proc.stdout
    lo, hi = re.search(r"WSR@1.5 over 1,000 cost vectors: ([0-9.]+) to ([0-9.]+)", proc.stdout).groups()
    assert 0.0 <= float(lo) <= float(hi) <= 1.0
    assert (folder / "bench" / "episodes.jsonl").is_file() and (folder / "bench" / "house.usda").is_file()


CHECKS = {"library": _check_library}
"""``<!-- snippet: NAME -->`` -> what the block's run must also show, beyond a zero exit status."""


def _runnable() -> list:
    params = []
    for b in python_blocks():
        if b.marker == "not run":
            continue
        marks = [pytest.mark.slow] if b.marker == "slow" else []
        params.append(pytest.param(b, id=b.id, marks=marks))
    return params


def test_named_snippets_exist():
    named = {b.marker_text for b in python_blocks() if b.marker == "snippet"}
    assert named == set(CHECKS), f"snippets named on the pages {named} and checks {set(CHECKS)} differ"
    library = next(b for b in python_blocks() if b.marker == "snippet" and b.marker_text == "library")
    assert library.path == DOCS / "getting-started.md"
    assert len([line for line in library.code.splitlines() if line.strip()]) <= 14


@pytest.mark.parametrize("block", _runnable())
def test_python_block_runs(block: Block, tmp_path):
    proc = subprocess.run([sys.executable, "-c", block.code], cwd=tmp_path, capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, f"{block.id} failed:\n{proc.stderr[-3000:]}"
    if block.marker == "snippet":
        CHECKS[block.marker_text](proc, tmp_path)


# ---------------------------------------------------------------------------
# the commands of the bash blocks
# ---------------------------------------------------------------------------

PARSER_MODULES = {
    "ignjax": "ignjax.__main__",
    "ignjax.sweep": "ignjax.sweep.cli",
    "ignjax.evaluate": "ignjax.evaluate.cli",
    "ignjax.build": "ignjax.build.cli",
    "ignjax.view": "ignjax.view.cli",
    "ignjax.bench": "ignjax.bench.runner",
}
"""``python -m X`` -> the module holding X's command line (X itself when not listed)."""
CONSOLE_SCRIPTS = {"ignjax-build": "ignjax.build"}
OPERATORS = {"&&", "||", ";", "|", "&", ";;"}
REDIRECTS = re.compile(r"^[<>]+&?$")


@dataclass(frozen=True)
class Command:
    where: str
    module: str  # the command's -m module
    args: tuple[str, ...]


def _words(line: str) -> list[str]:
    lex = shlex.shlex(line, posix=True, punctuation_chars=True)
    lex.whitespace_split = True
    lex.commenters = "#"
    return list(lex)


def commands_in(path: Path, text: str | None = None) -> list[Command]:
    """Each ``python -m ignjax...`` / ``ignjax-build`` command of ``path``'s bash blocks, with its arguments
    (line continuations joined, comments, redirections and other commands of the line dropped, shell
    variables read as 0)."""
    found = []
    for b in code_blocks(path, text):
        if b.lang not in ("bash", "sh", "shell", "console"):
            continue
        text = re.sub(r"\\\n", " ", b.code)
        for n, line in enumerate(text.splitlines()):
            if "ignjax" not in line:
                continue
            line = re.sub(r"\$\{?[A-Za-z_][A-Za-z_0-9]*\}?", "0", line)
            words, segments, current = _words(line), [], []
            i = 0
            while i < len(words):
                w = words[i]
                if w in OPERATORS:
                    segments.append(current)
                    current = []
                elif REDIRECTS.match(w):
                    if current and current[-1].isdigit():
                        current.pop()
                    i += 1  # the redirection's target
                else:
                    current.append(w)
                i += 1
            segments.append(current)
            for seg in segments:
                for k, w in enumerate(seg):
                    if w in CONSOLE_SCRIPTS:
                        found.append(Command(f"{b.id}+{n}", CONSOLE_SCRIPTS[w], tuple(seg[k + 1:])))
                        break
                    if re.fullmatch(r"python[0-9.]*", w) and seg[k + 1:k + 2] == ["-m"] and len(seg) > k + 2 \
                            and (seg[k + 2] == "ignjax" or seg[k + 2].startswith("ignjax.")):
                        found.append(Command(f"{b.id}+{n}", seg[k + 2], tuple(seg[k + 3:])))
                        break
    return found


def _settings_check(module: str, ns: argparse.Namespace, tmp: Path) -> None:
    """What the command checks of its settings before any work, where that needs no files of a run: the
    sweep's studies and configuration, the trainer's configuration, the evaluation's agents and ``--set``
    items (and the MLLM settings). Raises the command's own error."""
    if module == "ignjax.sweep":
        from ignjax.config import resolve
        from ignjax.sweep.cli import parse_studies

        parse_studies(ns.study)
        config = ns.config and str(ROOT / ns.config)
        assert config is None or Path(config).is_file(), f"--config {ns.config}: not a file of the repository"
        resolve(config, ns.sets, ns.quick)
    elif module == "ignjax.rl.train":
        from ignjax.rl import trainconfig

        config = ns.config and ROOT / ns.config
        trainconfig.resolve(str(config) if config and config.is_file() else None, ns.set)
    elif module == "ignjax.evaluate":
        from ignjax.agents import get_agent
        from ignjax.agents.llm.catalog import LLM_AGENTS, get_llm_agent
        from ignjax.evaluate.cli import llm_settings, parse_settings

        agents = [get_llm_agent(a) if a in LLM_AGENTS else get_agent(a) for a in ns.agent]
        _, _, sections = parse_settings(ns.set, [a.name for a in agents], ("llm", "views"))
        if any(a.name in LLM_AGENTS for a in agents):
            llm_settings(ns, sections, tmp)


def check_command(cmd: Command, tmp: Path) -> str | None:
    """None when ``cmd`` parses (and its settings check), else what is wrong."""
    target = PARSER_MODULES.get(cmd.module, cmd.module)
    try:
        module = importlib.import_module(target)
    except ImportError as e:
        return f"{cmd.where}: python -m {cmd.module}: cannot import {target}: {e}"
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            ns = module.build_parser().parse_args(list(cmd.args))
            _settings_check(cmd.module, ns, tmp)
    except SystemExit as e:
        if e.code not in (0, None):  # --help and --version exit 0
            return f"{cmd.where}: python -m {cmd.module} {shlex.join(cmd.args)}: {err.getvalue().strip()}"
    except Exception as e:  # noqa: BLE001 - the command's own error, reported with the command
        return f"{cmd.where}: python -m {cmd.module} {shlex.join(cmd.args)}: {type(e).__name__}: {e}"
    return None


def test_the_command_finder_reads_shell_lines():
    text = ("```bash\n"
            "pip install -e . && python -m ignjax.sweep --out r 2> err   # a comment\n"
            "srun --kill-on-bad-exit=1 python -m ignjax.sweep --process-id $I \\\n"
            "    --out /shared/sweep-$SLURM_JOB_ID\n"
            "ignjax-build scenes --out s | tee log\n"
            "python -m vllm.entrypoints.openai.api_server --model m\n"
            "```\n")
    found = commands_in(DOCS / "sample.md", text)
    assert [(c.module, c.args) for c in found] == [
        ("ignjax.sweep", ("--out", "r")),
        ("ignjax.sweep", ("--process-id", "0", "--out", "/shared/sweep-0")),
        ("ignjax.build", ("scenes", "--out", "s")),
    ]


def test_commands_on_the_pages_and_in_the_readme_parse(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)  # --config sweeps/... as a reader runs it, from the repository
    commands = [c for p in [*pages(), README] for c in commands_in(p)]
    assert len(commands) >= 40, f"only {len(commands)} commands found: is the finder broken?"
    assert {c.module for c in commands} >= {"ignjax.sweep", "ignjax.evaluate", "ignjax.build", "ignjax.bench",
                                            "ignjax.view", "ignjax.rl.train"}
    problems = [p for c in commands if (p := check_command(c, tmp_path))]
    assert not problems, "\n".join(problems)
    bad = Command("check", "ignjax.sweep", ("--studyy", "eval"))
    assert "unrecognized arguments" in check_command(bad, tmp_path)  # the check can fail
    bad = Command("check", "ignjax.evaluate", ("--agent", "eig", "--set", "sim.no_such_key=1"))
    assert check_command(bad, tmp_path) is not None


# ---------------------------------------------------------------------------
# the site
# ---------------------------------------------------------------------------


def nav_pages() -> set[str]:
    """The pages ``mkdocs.yml``'s ``nav`` lists, relative to ``docs/``."""
    text = (ROOT / "mkdocs.yml").read_text().split("\nnav:", 1)[1]
    return set(re.findall(r"([\w./-]+\.md)\s*$", text, re.M))


def test_every_page_is_in_nav():
    on_disk = {p.relative_to(DOCS).as_posix() for p in pages()}
    assert nav_pages() == on_disk, f"in nav only: {nav_pages() - on_disk}; not in nav: {on_disk - nav_pages()}"


def _slug(heading: str) -> str:
    """A heading's anchor as GitHub and Python-Markdown's toc both make it for our headings."""
    text = re.sub(r"[`*_]|<[^>]+>", "", heading).strip().lower()
    return re.sub(r"\s", "-", re.sub(r"[^\w\s-]", "", text))


def prose(path: Path) -> str:
    """``path``'s text with the lines of its code blocks blanked."""
    lines = path.read_text().splitlines()
    for b in code_blocks(path):
        lines[b.line - 1:b.end] = [""] * (b.end - b.line + 1)
    return "\n".join(lines)


def anchors(path: Path) -> set[str]:
    """The anchors of a page: its headings' and its ``id="..."`` attributes."""
    text = prose(path)
    heads = {_slug(m.group(1)) for m in re.finditer(r"(?m)^#{1,6}\s+(.+?)\s*#*\s*$", text)}
    return heads | set(re.findall(r'id="([^"]+)"', text))


def relative_links(path: Path) -> list[str]:
    """The relative targets of ``path``'s Markdown links and images (outside code)."""
    text = re.sub(r"`[^`\n]*`", "", prose(path))
    targets = re.findall(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", text)
    targets += re.findall(r'<img[^>]+src="([^"]+)"', text)
    return [t for t in targets if not re.match(r"^[a-z][a-z0-9+.-]*:|^#|^/", t)]


@pytest.mark.parametrize("path", [README, *pages()], ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_and_images_exist(path: Path):
    """mkdocs checks the pages' links too (strictly); this also covers the README, which it does not build, and
    runs without the docs extra."""
    for target in relative_links(path):
        file, _, anchor = target.partition("#")
        dest = (path.parent / file).resolve()
        assert dest.exists(), f"{path.relative_to(ROOT)}: {target}: no such file"
        if anchor and dest.suffix == ".md":
            assert anchor in anchors(dest), f"{path.relative_to(ROOT)}: {target}: no such heading in {file}"


def _importable(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except ImportError:
        return False


def test_site_builds_strictly(tmp_path):
    missing = [m for m in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers") if not _importable(m)]
    if missing:
        pytest.skip(f"the documentation tools are not installed ({', '.join(missing)}): pip install -e \".[docs]\"")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                          cwd=ROOT, capture_output=True, text=True, timeout=600, env=env)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-5000:]
    for page in nav_pages():
        name = page[:-3]  # mkdocs' directory URLs: a.md -> a/index.html, a/index.md -> a/index.html
        html = tmp_path / "site" / (name + ".html" if name.split("/")[-1] == "index" else name + "/index.html")
        assert html.is_file(), f"{page} was not built"
    api = (tmp_path / "site" / "api" / "sim" / "index.html").read_text()
    assert 'id="ignjax.sim.env.step"' in api and ":func:" not in api  # API entries, their roles rendered as links


# ---------------------------------------------------------------------------
# the README as the front page
# ---------------------------------------------------------------------------


def test_readme_is_a_short_front_page_that_starts_with_the_two_commands():
    text = README.read_text()
    assert len(text.splitlines()) <= README_MAX_LINES
    first = code_blocks(README)[0]
    assert first.lang == "bash" and first.code.splitlines() == FIRST_BLOCK
    assert text.index("```") < text.index("\n## ")  # before any section
    assert FIRST_BLOCK[1] in (ROOT / ".ci" / "run").read_text().splitlines()  # the line CI runs
    for page in ("docs/getting-started.md", "docs/sweep.md", "docs/mllm.md", "docs/scenes.md", "docs/agents.md"):
        assert f"]({page}" in text, f"the README does not link {page}"
