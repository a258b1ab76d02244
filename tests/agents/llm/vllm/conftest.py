"""A live vLLM server (CPU build) serving the tiny Qwen2-VL-style model.

``vllm_server`` (session scope) starts the server with
:func:`ignjax.agents.llm.vllm_server.start_vllm_server` (settings and the
reasons for them in that module's docstring) and yields its
:class:`~ignjax.agents.llm.vllm_server.VllmServer` (``base_url`` =
``http://127.0.0.1:PORT/v1``, ``model`` = ``"tiny-vl"``, ``log_path``,
``model_dir``, ``max_model_len``, ``max_images``, ``pid``); the server's
whole process group is stopped at the end. Where the environment that
``.ci/prepare-vllm`` builds under ``${IGNJAX_VLLM_HOME:-~/.cache/ignjax/vllm}``
is absent (not prepared, no torch CPU wheel on the machine, install failed)
the tests skip with the reason ``prepare-vllm`` recorded; a server that
exits or does not answer within ``IGNJAX_VLLM_START_TIMEOUT`` seconds
(default 180) fails them with the tail of its log.
"""

from __future__ import annotations

import contextlib

import pytest

from ignjax.agents.llm.vllm_server import (
    VllmServer,
    VllmServerError,
    environment_problem,
    start_vllm_server,
    vllm_home,
)


@pytest.fixture(scope="session")
def vllm_server(tmp_path_factory) -> VllmServer:
    home = vllm_home()
    problem = environment_problem(home)
    if problem:
        pytest.skip(f"vLLM server environment not prepared: run .ci/prepare-vllm ({problem})")
    log_path = tmp_path_factory.mktemp("vllm-server") / "server.log"
    with contextlib.ExitStack() as stack:
        try:
            srv = stack.enter_context(start_vllm_server(home, log_path=log_path))
        except VllmServerError as exc:
            pytest.fail(str(exc))
        yield srv
