"""Suite-wide set-up: the result cache lives in a temporary folder, never in the user's cache."""

import pytest


@pytest.fixture(autouse=True, scope="session")
def _result_cache_folder(tmp_path_factory):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("AFFINITY_CACHE_DIR", str(tmp_path_factory.mktemp("result-cache")))
        yield
