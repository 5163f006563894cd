import matplotlib

matplotlib.use("Agg")


import matplotlib.pyplot as plt
import pytest


@pytest.fixture(autouse=True)
def _close_test_figures():
    """Figures a test draws itself are closed after it (the CLI closes its own)."""
    yield
    plt.close("all")
