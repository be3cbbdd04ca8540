import pytest

import tactsense as ts


@pytest.fixture(scope="session")
def initial():
    return ts.fearing1990_initial()


@pytest.fixture(scope="session")
def improved():
    return ts.fearing1990_improved()


@pytest.fixture(params=["initial", "improved"], scope="session")
def any_preset(request):
    return ts.preset(request.param)


# ---- the joint fit's tables kept in a folder of the session's own (r8-padjoint) ----
@pytest.fixture(autouse=True, scope="session")
def _table_cache_folder(tmp_path_factory):
    """The pad fit's tables and the frames' (``physics._hertz_table.cached_response_table``) go to a temporary
    folder, not the user's cache."""
    import os

    os.environ.setdefault("TACTSENSE_CACHE_DIR", str(tmp_path_factory.mktemp("table_cache")))
