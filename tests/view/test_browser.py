"""The page in a real browser: headless Chromium (Debian's ``chromium`` and
``chromium-driver``, installed by ``.ci/run`` when missing) driven by
Selenium with the system chromedriver; Selenium Manager is kept offline, so
nothing is downloaded. Skipped, with the reason, when either is absent
(a failure under CI=true).

Checked in the DOM: one ``data-episode-id`` row per episode in the index,
filters and sorting against the outcome table, the step slider moving the
agent marker (its SVG coordinates) from the start to the final pose, a step
list as long as the trajectory, the oracle's answer at an ASK step, two
agents side by side, images and transcripts from the run folder, a page
that opens as one file (DOMContentLoaded fired, nothing else fetched), and
no message on the browser's console."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from ignjax.evaluate.outcomes import read_outcomes, read_trajectories
from ignjax.view.cli import main

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMEDRIVER = shutil.which("chromedriver") or ("/usr/bin/chromedriver" if Path("/usr/bin/chromedriver").is_file() else None)


@pytest.fixture(scope="module")
def browser():
    webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed (pip install -e '.[dev]')")
    if not CHROMIUM or not CHROMEDRIVER:
        pytest.skip("headless Chromium is not installed: apt-get install chromium chromium-driver (.ci/run does)")
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    os.environ["SE_OFFLINE"] = "true"  # Selenium Manager must not download a browser or a driver
    opts = Options()
    opts.binary_location = CHROMIUM
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1400,1000"):
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    yield driver
    driver.quit()


def open_page(driver, path: Path, fragment: str = ""):
    driver.get("about:blank")  # a fresh load (only the fragment changing would keep the page and its state)
    driver.get(path.resolve().as_uri() + fragment)
    assert driver.execute_script("return document.body.dataset.ready") is not None, "the page script did not finish"


def console(driver) -> list[dict]:
    """Messages on the browser's console since the last call (errors, warnings, logs)."""
    return [e for e in driver.get_log("browser")]


def css(driver, selector: str, root=None):
    return (root or driver).find_elements("css selector", selector)


@pytest.fixture(scope="module")
def page(eval_run, tmp_path_factory):
    out = tmp_path_factory.mktemp("page") / "viewer.html"
    assert main([str(eval_run), "--out", str(out)]) == 0
    rows = read_outcomes(eval_run / "outcomes.csv")
    meta, traj = read_trajectories(eval_run / "trajectories.npz")
    return {"path": out, "rows": rows, "ids": meta["episode_ids"], "traj": traj}


def test_index_has_one_row_per_episode_and_loads_as_one_file(browser, page):
    open_page(browser, page["path"])
    rows = css(browser, "#index tbody tr[data-episode-id]")
    assert [r.get_attribute("data-episode-id") for r in rows] == page["ids"]
    assert len(css(browser, "[data-episode-id]")) == len(page["ids"]) == 40
    dcl, external = browser.execute_script(
        "return [performance.getEntriesByType('navigation')[0].domContentLoadedEventEnd,"
        " [...document.querySelectorAll('[src], link[href]')].map(e => e.getAttribute('src') || e.getAttribute('href'))"
        " .filter(u => !u.startsWith('data:'))]")
    assert dcl > 0 and external == []  # DOMContentLoaded fired and ran its handlers; the page loads no other file
    assert console(browser) == []


def _shown(driver) -> list[str]:
    return [r.get_attribute("data-episode-id") for r in css(driver, "#index tbody tr[data-episode-id]") if r.is_displayed()]


def test_filters_and_sorting_follow_the_outcomes(browser, page):
    from selenium.webdriver.support.ui import Select

    open_page(browser, page["path"])
    eig = {r["episode_id"]: r for r in page["rows"] if r["agent"] == "eig"}
    Select(browser.find_element("id", "f-diff")).select_by_value("hard")
    assert sorted(_shown(browser)) == sorted(e for e, r in eig.items() if r["difficulty"] == "hard")
    Select(browser.find_element("id", "f-diff")).select_by_value("")
    browser.find_element("css selector", "#filters input[data-agent=random]").click()  # eig only
    Select(browser.find_element("id", "f-out")).select_by_value("ok")
    Select(browser.find_element("id", "f-tau")).select_by_visible_text("1.5 m")
    assert sorted(_shown(browser)) == sorted(e for e, r in eig.items() if r["final_distance"] <= 1.5)
    Select(browser.find_element("id", "f-out")).select_by_value("")
    Select(browser.find_element("id", "f-ask")).select_by_value("4")
    assert sorted(_shown(browser)) == sorted(e for e, r in eig.items() if r["q4"] > 0)
    Select(browser.find_element("id", "f-ask")).select_by_value("")
    browser.find_element("css selector", "th[data-key='a:0:fd']").click()  # sort by eig's final distance
    shown = _shown(browser)
    assert shown == sorted(eig, key=lambda e: (round(eig[e]["final_distance"], 2), page["ids"].index(e)))
    assert console(browser) == []


def _episode(page, agent="eig"):
    """Row index and outcome of the agent's episode with the most steps among those that asked."""
    rows = [r for r in page["rows"] if r["agent"] == agent]
    r = max(rows, key=lambda r: (r["n_questions"] > 0, r["steps"]))
    return page["ids"].index(r["episode_id"]), r


def _marker(driver, panel):
    m = css(driver, "circle.agent-marker", panel)[0]
    return float(m.get_attribute("cx")), float(m.get_attribute("cy"))


def test_slider_moves_the_marker_along_the_trajectory(browser, page):
    i, row = _episode(page)
    open_page(browser, page["path"], f"#ep={i}&a=eig")
    (panel,) = css(browser, ".panel")
    assert panel.get_attribute("data-agent") == "eig"
    pose = page["traj"]["eig"]["pose"][i]
    n = row["steps"]
    assert len(css(browser, "ol.step-list li", panel)) == n == int((page["traj"]["eig"]["kind"][i] >= 0).sum())
    slider = css(browser, "input.step-slider", panel)[0]
    assert slider.get_attribute("max") == str(n)
    assert _marker(browser, panel) == pytest.approx(tuple(pose[0, :2]), abs=0.006)
    browser.execute_script("arguments[0].value = arguments[0].max; arguments[0].dispatchEvent(new Event('input'))", slider)
    assert _marker(browser, panel) == pytest.approx(tuple(pose[n, :2]), abs=0.006)
    assert np.linalg.norm(pose[n, :2] - pose[0, :2]) > 0.05  # so the marker did move
    assert "Episode ended by" in css(browser, ".detail", panel)[0].text
    # a click on an ASK step of the list shows the question and the oracle's answer
    kinds = page["traj"]["eig"]["kind"][i]
    t = int(np.nonzero(kinds == 1)[0][0])
    css(browser, f"ol.step-list li[data-step='{t}']", panel)[0].click()
    assert slider.get_attribute("value") == str(t)
    detail = css(browser, ".detail", panel)[0].text
    answer = browser.execute_script("return JSON.parse(document.getElementById('ignjax-data').textContent)"
                                    ".episodes[arguments[0]].runs[0].ans[arguments[1]]", i, t)
    assert answer and f"Step {t}: ASK Type {page['traj']['eig']['question'][i, t]}" in detail
    assert f"Oracle: {answer}" in detail
    assert _marker(browser, panel) == pytest.approx(tuple(pose[t, :2]), abs=0.006)
    assert console(browser) == []


def test_two_agents_side_by_side(browser, page):
    i, _ = _episode(page)
    open_page(browser, page["path"], f"#ep={i}&a=eig&b=random")
    panels = css(browser, ".panel")
    assert [p.get_attribute("data-agent") for p in panels] == ["eig", "random"]
    for p, agent in zip(panels, ("eig", "random")):
        row = next(r for r in page["rows"] if r["agent"] == agent and r["episode_id"] == page["ids"][i])
        assert len(css(browser, "ol.step-list li", p)) == row["steps"]
    # the index's episode link opens the first two agents shown side by side
    browser.find_element("css selector", "a[href='#']").click()
    css(browser, f"#index tbody tr[data-row='{i}'] td a", None)[0].click()
    from selenium.webdriver.support.ui import WebDriverWait

    # the click changes the fragment; the page draws the panels on the hashchange that follows
    WebDriverWait(browser, 10).until(lambda d: css(d, ".panel"))
    assert [p.get_attribute("data-agent") for p in css(browser, ".panel")] == ["eig", "random"]
    assert console(browser) == []


def _png(color) -> bytes:
    import imageio.v3 as iio

    img = np.zeros((48, 64, 3), np.uint8)
    img[...] = color
    return iio.imwrite("<bytes>", img, extension=".png")


def test_images_and_transcripts_are_shown(browser, run_copy, tmp_path, small_benchmark):
    ep = small_benchmark["set"].records[0]["episode_id"]
    folder = run_copy / "images" / "eig" / ep
    folder.mkdir(parents=True)
    (folder / "000_panel.png").write_bytes(_png((200, 30, 30)))
    (folder / "000_grounder.png").write_bytes(_png((30, 200, 30)))
    call = {"agent": "eig", "episode": ep, "step": 0, "role": "planner", "prompt": "PROMPT TEXT </script>",
            "reply": "RAW REPLY", "parsed": {"kind": "MOVE", "direction": 2}, "retries": [{"reply": "junk", "error": "bad"}],
            "error": None}
    (run_copy / "transcripts.jsonl").write_text(json.dumps(call) + "\n")
    out = tmp_path / "img.html"
    assert main([str(run_copy), "--out", str(out), "--episodes", "2"]) == 0
    open_page(browser, out, "#ep=0&a=eig")
    (panel,) = css(browser, ".panel")
    imgs = css(browser, ".images img", panel)
    assert len(imgs) == 2
    assert [browser.execute_script("return arguments[0].naturalWidth", im) for im in imgs] == [64, 64]
    kind0 = int(read_trajectories(run_copy / "trajectories.npz")[1]["eig"]["kind"][0, 0])
    assert len(css(browser, ".grounder .cell", panel)) == (1 if kind0 == 0 else 0)
    assert css(browser, ".call pre.reply", panel)[0].text == "RAW REPLY"
    assert '"direction": 2' in css(browser, ".call pre.parsed", panel)[0].text
    prompt = css(browser, ".call pre.prompt", panel)[0]
    assert browser.execute_script("return arguments[0].textContent", prompt) == "PROMPT TEXT </script>"
    assert "1 retry" in css(browser, ".call", panel)[0].text
    assert console(browser) == []


def test_a_vlm_run_from_the_local_model_server(browser, tmp_path):
    """A run of the ``vlm`` agent through ``python -m ignjax.evaluate`` against
    the scripted server (transcripts and panels written by the host loop):
    the page shows each step's panel and the model call of that step."""
    from ignjax.agents.llm.serve import ScriptedServer
    from ignjax.evaluate.cli import main as evaluate

    root = Path(__file__).resolve().parents[2]
    out = tmp_path / "vlm"
    with ScriptedServer() as srv:
        assert evaluate(["--episodes", str(root / "scenes" / "benchmark.jsonl.gz"), "--agent", "vlm",
                         "--llm-endpoint", srv.base_url, "--llm-model", srv.model, "--limit", "2", "--save-images", "1",
                         "--set", "sim.max_steps=4", "--set", "views.size=64", "--out", str(out), "--quiet"]) == 0
    calls = [json.loads(line) for line in (out / "transcripts" / "vlm.jsonl").read_text().splitlines()]
    page = tmp_path / "vlm.html"
    assert main([str(out), "--out", str(page), "--episodes", "1"]) == 0
    open_page(browser, page, "#ep=0&a=vlm")
    (panel,) = css(browser, ".panel")
    assert panel.get_attribute("data-agent") == "vlm"
    first = [c for c in calls if c["episode"] == calls[0]["episode"] and c["step"] == 0][0]
    assert css(browser, ".call pre.reply", panel)[0].text == first["reply"]
    prompt = browser.execute_script("return arguments[0].textContent", css(browser, ".call pre.prompt", panel)[0])
    assert prompt == first["prompt"] and "Find the" in prompt
    imgs = css(browser, ".images img", panel)
    assert imgs and browser.execute_script("return arguments[0].naturalWidth", imgs[0]) == 3 * 64
    assert console(browser) == []
