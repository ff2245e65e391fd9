"""`modc view DIR/ranking.json` in headless Chromium (the fixtures and helpers of
test_view_browser.py): the list of designs heads the panel, "play" runs the first design's task
with its segment named in the page, and picking the second design in the list loads its robot."""
from __future__ import annotations

import json

import numpy as np
import pytest
from test_view_browser import BROWSER, SLIDERS, _settle, _wait, chromium, page_text, running
from test_view_ranking import Q_A, _file_q, _make

from modc.view.ranking import Ranking, RankingPage

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(BROWSER is None, reason="no Chromium installed (Debian: apt-get install chromium)")]

@pytest.fixture
def chrome():
    with chromium() as tools:
        yield tools


INPUT_VALUES = "[...document.querySelectorAll('input')].map(i => i.value)"


def _press(browser, box) -> None:
    for kind in ("mousePressed", "mouseReleased"):
        browser.call("Input.dispatchMouseEvent", type=kind, x=box[0], y=box[1], button="left", clickCount=1)


def _centre(browser, selector: str, text: str, by_value: bool = False):
    """The centre of the first element matching selector whose text (or input value) is text."""
    key = "value" if by_value else "textContent"
    return browser.js(f"""(() => {{ const e = [...document.querySelectorAll({json.dumps(selector)})]
        .find(e => (e.{key} || '').trim() === {json.dumps(text)});
        if (!e) return null;
        e.scrollIntoView({{block: 'center'}});  // the panel of a task design is taller than the window
        const r = e.getBoundingClientRect(); return [r.x + r.width / 2, r.y + r.height / 2]; }})()""")


def test_the_page_plays_a_design_task_and_switches_design(chrome, tmp_path):
    ranking = Ranking(_make(tmp_path / "out"))
    page = RankingPage(ranking)
    with running(page) as (server, view):
        chrome.call("Page.navigate", url=view.url)
        _wait(lambda: chrome.js(SLIDERS) == 4, 60, "3 joint sliders and the time slider")
        _settle(chrome, server)
        assert ranking.choice(0) in chrome.js(INPUT_VALUES)  # the list, on the first design
        assert "home → a" in page_text(chrome)
        _wait(lambda: page.t > 0 or _press(chrome, _centre(chrome, "button", "play")), 60, "playback to start")
        _wait(lambda: not page.playing, 120, "the task to play to its end")
        end = page.source.trajectory.t[-1]
        assert page.t == pytest.approx(end)
        assert np.allclose(page.q, _file_q(ranking.traj(0), end), atol=1e-9)
        _wait(lambda: "segment 1 of 1: a → b" in page_text(chrome), 30, "the last segment named")

        box = _centre(chrome, "input", ranking.choice(0), by_value=True)
        assert box, "no list of designs in the page"
        _press(chrome, box)
        option = _wait(lambda: _centre(chrome, "[role=option]", ranking.choice(1)), 30, "the list's options")
        _press(chrome, option)
        _wait(lambda: page.index == 1 and chrome.js(SLIDERS) == 4 and "τnom" in page_text(chrome), 60,
              "design 2's 4 joint sliders")
        assert page.arm.robot.name == "small_2" and page.q == pytest.approx(tuple(Q_A))
        # the panel's text follows the server's update: wait for it, as for the sliders above
        _wait(lambda: "small_2" in page_text(chrome) and ranking.choice(1) in chrome.js(INPUT_VALUES), 60,
              "design 2's name and list entry in the page")
