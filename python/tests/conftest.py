"""Shared fixtures: one renderer for the session (its device and pipelines are
made once), and the `gnomon` command line the arrays are checked against."""

import os
import pathlib
import shutil

import pytest

import gnomon

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def renderer():
    return gnomon.Renderer()


@pytest.fixture(scope="session")
def cli():
    """The command line to compare with: $GNOMON_CLI, or the repository's release
    build (`cargo build --release`), or `gnomon` on the PATH."""
    candidates = [os.environ.get("GNOMON_CLI"), REPO / "target" / "release" / "gnomon", shutil.which("gnomon")]
    for candidate in candidates:
        if candidate and pathlib.Path(candidate).is_file():
            return str(candidate)
    pytest.fail("no `gnomon` command line: build it with `cargo build --release`, or set GNOMON_CLI")
