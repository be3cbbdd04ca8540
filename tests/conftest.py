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
