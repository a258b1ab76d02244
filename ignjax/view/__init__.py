"""The episode viewer: ``python -m ignjax.view RUN_DIR`` writes one
self-contained HTML page (inline script, style, map data and images; no
server, no network) that replays the episodes of an evaluation or sweep run
folder; ``--gif EPISODE`` exports one episode as an animated GIF or MP4.

::

    python -m ignjax.view RUN_DIR [--out FILE.html] [--episodes N] [--agent NAME ...]
                                  [--benchmark EPISODE_FILE] [--scenes-root DIR] [--title TEXT]
    python -m ignjax.view RUN_DIR --gif EPISODE_ID [--agent NAME] [--out FILE.gif|FILE.mp4] [--fps 2]

The page has an **index** (one row per episode, ``data-episode-id``; per
agent: success at each threshold, final distance, WSR discount, questions by
type, stop reason; sortable by any column, filtered by agent, difficulty,
success or failure at a threshold, asked type, and agents that disagree) and
an **episode page** per episode and agent (``#ep=<row>&a=<agent>[&b=<agent>]``;
two agents side by side): the top-down map drawn as SVG (rooms, walls, doors,
instances; the target and its same-category distractors highlighted; the
start), the path step by step under a slider, and at each step the decision
(MOVE with view and grid cell, ASK with type and question, STOP), the
oracle's answer in words (:mod:`ignjax.sim.oracle_text`), the running cost
discount, blocked headings, and what the agent saw: the rendered panel and
the Grounder view with the chosen cell marked when the run has images, the
symbolic observation (room, instances in sight) otherwise, and for model
agents the prompt, the raw reply, the parse result and retries of each call.

What a run folder holds, and what the viewer reads
--------------------------------------------------

Written by ``python -m ignjax.evaluate`` and ``python -m ignjax.sweep``:

``outcomes.parquet`` or ``outcomes.csv``
    one row per agent and episode (:mod:`ignjax.evaluate.outcomes`); a folder
    without either is not a run folder.
``trajectories.npz``
    every agent's per-step :class:`~ignjax.sim.types.Trajectory` with the
    episode file, category vocabulary, thresholds, costs, success rule and
    simulator settings (:func:`ignjax.evaluate.outcomes.write_trajectories`).
    The scenes are read from the episode file it names (``--benchmark`` and
    ``--scenes-root`` when it moved).
``run.json``
    optional here: the page title is the sweep's ``config.run.name`` when
    present, else the folder's name.

Written by agents that see images or call models (optional; shown when present):

``images/<agent>/<episode_id>/<step>_panel.<ext>`` and ``<step>_grounder.<ext>``
    the Planner's panel and the Grounder's view the agent decided on at
    planner step ``<step>`` (0-based, as in the outcomes' question trace;
    zero padding allowed); ``<ext>`` is ``jpg``, ``jpeg`` or ``png``; the
    episode id's ``/`` are folder separators
    (``images/eig/house_0_000/tv_stand_0/2/003_panel.jpg``). On the
    Grounder view the page marks the chosen MOVE's cell (column 1..8 left to
    right, row 1..8 bottom to top). ``<step>_grounder_<view>.<ext>`` (the
    view's index added) is read as ``<step>_grounder.<ext>``.
``transcripts.jsonl`` and ``transcripts/*.jsonl``
    one JSON object per line, one line per model call, with the keys
    ``agent`` (str), ``episode`` (the episode id), ``step`` (int, 0-based
    planner step), ``role`` (``"planner"``, ``"grounder"``, ``"controller"``:
    a decision taken without a model call, ``"paraphrase"``: an oracle
    answer reworded by the model, or ``"caption"``: one view described by
    the model for an agent that reads captions), ``prompt``
    (str, the text sent), ``reply`` (str, the raw reply), ``parsed`` (any
    JSON value: the parse result, null when parsing failed), ``retries``
    (int, or a list of ``{"reply": str, "error": str}`` earlier attempts)
    and ``error`` (str or null); a ``controller`` record may carry ``rule``
    (str: the rule that decided) and ``text`` (str: what it asked or did),
    shown with it; other keys are ignored, and so are records
    of agents or episodes the page does not hold. Calls are shown in file
    order. A line that is not such an object is an error naming the file
    and line.

Size: without images a page holds every episode; images are embedded
(base64) only for the episodes asked for with ``--episodes N`` (the first
N of the run, which are then the only episodes in the page). Transcripts
are text and always embedded for the episodes in the page. The page for the
shipped benchmark (500 episodes x 5 agents) is 4.0 MB and opens in about 0.6-0.9 s
in headless Chromium (DOMContentLoaded on a 2-core machine).

The same run folder gives the same HTML bytes (no time stamps, sorted
keys, rounded coordinates). The page is written atomically
(:func:`ignjax.fileio.atomic_write`), after every input was read and checked.

Modules: :mod:`~ignjax.view.runfolder` (read and check a run folder:
:func:`~ignjax.view.runfolder.read_run`), :mod:`~ignjax.view.mapdata`
(scenes as map data), :mod:`~ignjax.view.page` (the page's data and HTML:
:func:`~ignjax.view.page.build_page`, :func:`~ignjax.view.page.write_page`),
:mod:`~ignjax.view.script` and :mod:`~ignjax.view.style` (the inline script
and style sheet), :mod:`~ignjax.view.export` (GIF/MP4) and
:mod:`~ignjax.view.cli` (the command line). This package file imports none
of them, so ``--help`` answers at once.

May import: everything below layer 6 (it reads run folders, like the
command lines it sits with); nothing imports it but :mod:`ignjax.sweep`.
"""
