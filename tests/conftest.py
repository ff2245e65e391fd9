"""Shared test helpers: compile .mod text or files into a temporary output tree."""
from __future__ import annotations

import resource
import subprocess
from pathlib import Path

import pytest

from modc.compiler import Checked, build, check_file, check_text, write_tree

ROOT = Path(__file__).resolve().parent.parent
# the small design cell several design tests search: two targets around a post, 3 units of H1/L3
SMALL_CELL = """\
design small {
    payload 100 g
    box post size (0.05, 0.05, 0.6) m at (0.2, 0.25, 0.3) m
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m
    units 3
    modules H1, L3
}
"""
# the design benchmark's cell (benchmarks/bench_design.CELL): three targets, a shelf and a post
THREE_TARGETS = """design three {
    payload 100 g
    box shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.05) m
    box post size (0.05, 0.05, 0.6) m at (0.15, 0.3, 0.3) m
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m
    target c at (0.10, 0.30, 0.45) m
    units 2 to 3
}
"""
EXAMPLES = sorted((ROOT / "examples").glob("*.mod"))
# examples with at least one arm (farm_cell.mod holds only a `design` problem)
ARM_EXAMPLES = [
    p for p in EXAMPLES if any(ln.startswith("robot ") for ln in p.read_text(encoding="utf-8").splitlines())
]


def modc_design(tmp_path: Path, text: str, *args: str, timeout: float = 900) -> subprocess.CompletedProcess:
    """`modc design` run as a user runs it, on `text` written to tmp_path/cell.mod, into
    tmp_path/out (quiet, no pictures), with a private cache."""
    import os
    import sys

    src = tmp_path / "cell.mod"
    src.write_text(text, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=str(ROOT), MODC_CACHE_DIR=str(tmp_path / "cache"), PYTHONWARNINGS="ignore")
    return subprocess.run([sys.executable, "-m", "modc", "design", str(src), "-o", str(tmp_path / "out"), "-q",
                           "--no-render", *args], capture_output=True, text=True, env=env, timeout=timeout)


def checked_ok(text: str, path: str = "t.mod") -> Checked:
    c = check_text(text, path)
    errors = [d for d in c.diagnostics if d.is_error]
    assert not errors, "\n".join(f"{d.code}: {d.message}" for d in errors)
    return c


def compile_text(text: str, out: Path, path: str = "t.mod") -> dict[str, str | bytes]:
    """Check, build and write; returns the files written (relative path -> content)."""
    c = checked_ok(text, path)
    files = build(c)
    write_tree(files, out)
    return files


def compile_file(path: Path, out: Path) -> dict[str, str | bytes]:
    c = check_file(path)
    errors = [d for d in c.diagnostics if d.is_error]
    assert not errors, "\n".join(f"{d.code}: {d.message}" for d in errors)
    files = build(c)
    write_tree(files, out)
    return files


@pytest.fixture(scope="session")
def compiled_examples(tmp_path_factory) -> dict[str, Path]:
    """Every example compiled once per session: example stem -> output directory."""
    out = {}
    for ex in EXAMPLES:
        d = tmp_path_factory.mktemp(ex.stem) / "out"
        compile_file(ex, d)
        out[ex.stem] = d
    return out


def random_units(rng, variant, link_max_mm: int) -> list[str]:
    """1-6 units of the paper's four types with realisable random twists (and links on types 3/4),
    each in the variant variant(i, n) says: the random chains the property tests share."""
    n = rng.randint(1, 6)
    units = []
    for i in range(n):
        kind = rng.randint(1, 4)
        params = [f"pivot={rng.choice(range(-90, 91, 15))}deg"]
        if kind >= 3:
            params += [f"port={rng.choice(range(-180, 181, 15))}deg", f"link={rng.randint(50, link_max_mm)}mm"]
        units.append(f"{variant(i, n)}{kind}({', '.join(params)})")
    return units


def run_cpu(cmd: list[str], *, timeout: float = 600, **kw) -> tuple[subprocess.CompletedProcess, float]:
    """subprocess.run(cmd, capture_output=True, text=True) and the CPU seconds the child (with its own
    children) used. CPU time, unlike wall-clock time, does not grow with the rest of the machine's
    load: a bound on it is a bound on the work done. `timeout` is a guard against hangs only."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kw)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


# Slow tests (over ~2 s alone, measured with --durations) in files whose owners mark them there in
# time: `-m "not slow"` leaves them out all the same. Tests elsewhere carry @pytest.mark.slow.
SLOW_ELSEWHERE = frozenset({
    "tests/test_design.py::test_modc_design_writes_compilable_robots",
    "tests/test_design.py::test_report_html_shows_the_top_design",
    "tests/test_design.py::test_cli_engines_give_the_same_ranking",
    "tests/test_plan.py::test_target_only_in_collision",
    "tests/test_plan.py::test_obstacle_shapes_agree_with_the_independent_check",
    "tests/test_design.py::test_search_is_identical_for_any_number_of_workers_and_dask",
    "tests/test_hostile_strings.py::test_metacharacters_in_the_file_name_and_library_text_give_valid_outputs",
    "tests/test_hostile_strings.py::test_no_output_expands_user_text",
    "tests/test_library.py::test_user_library_file_is_used",
    "tests/test_lint_formats.py::test_format_golden",
    "tests/test_lint_formats.py::test_github_annotations_are_workflow_commands",
    "tests/test_lint_formats.py::test_globs_and_directories",
    "tests/test_lint_formats.py::test_sarif_fingerprints_survive_moved_lines",
    "tests/test_lint_formats.py::test_sarif_is_valid_sarif_2_1_0",
    "tests/test_lint_formats.py::test_sarif_multitool_validates",
    "tests/test_lint_formats.py::test_sarif_root_and_files_outside_it",
    "tests/test_lint_formats.py::test_sarif_rules_carry_their_meaning_and_help",
    "tests/test_lint_formats.py::test_sarif_uris_are_percent_encoded_references_under_srcroot",
    "tests/test_lsp.py::test_diagnostics_on_open_and_cleared_by_a_fix",
    "tests/test_lsp.py::test_exit_without_shutdown_and_closed_stdin_end_the_process",
    "tests/test_lsp.py::test_initialize_advertises_features",
    "tests/test_lsp_transport.py::test_the_server_survives_a_huge_content_length",
    "tests/test_mjcf.py::test_every_example_passes_sim_in_mujoco",
    "tests/test_mjcf.py::test_mujoco_catches_tampered_kinematics_and_inertials",
    "tests/test_mjcf.py::test_mujoco_self_collision_and_srdf_pairs",
    "tests/test_output.py::test_compile_writes_the_normative_layout",
    "tests/test_output.py::test_exit_codes_and_no_traceback",
    "tests/test_output.py::test_failed_compile_creates_no_out",
    "tests/test_output.py::test_failed_compile_leaves_out_untouched",
    "tests/test_output.py::test_only_selects_backends",
    "tests/test_output.py::test_recompile_replaces_stale_files",
    "tests/test_output.py::test_refuses_to_replace_a_foreign_directory",
    "tests/test_output.py::test_several_robots_give_several_urdfs",
    "tests/test_output.py::test_two_compiles_are_byte_identical",
    "tests/test_plan.py::test_farm_needs_a_detour",
    "tests/test_plan.py::test_farm_path_collision_free",
    "tests/test_plan.py::test_other_seed_also_valid",
    "tests/test_plan.py::test_same_seed_same_json",
    "tests/test_view.py::test_busy_port_is_a_clean_error",
    "tests/test_view.py::test_ctrl_c_stops_cleanly",
    "tests/test_view.py::test_unknown_robot_and_bad_ranking_exit_2",
    "tests/test_view_browser.py::test_buttons_page_the_ranking_go_to_poses_and_play",
    "tests/test_view_browser.py::test_page_shows_the_arm_and_a_slider_moves_it",
    "tests/test_view_browser.py::test_saving_the_file_updates_the_page_within_a_second",
})


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.nodeid.split("[")[0] in SLOW_ELSEWHERE:
            item.add_marker(pytest.mark.slow)


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", help="rewrite tests/golden from the current output")


@pytest.fixture
def update_golden(request) -> bool:
    import os

    return bool(request.config.getoption("--update-golden") or os.environ.get("MODC_UPDATE_GOLDEN"))
