import pytest


def pytest_addoption(parser):
    parser.addoption("--stepbench", required=True, help="path to the stepbench executable")


@pytest.fixture(scope="session")
def stepbench(request):
    return request.config.getoption("--stepbench")
