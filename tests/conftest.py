"""Hypothesis profiles: ``ci`` (default, few derandomized examples) and ``deep``."""

import os

# every reconstruction in the suite runs the expensive self-checks
os.environ["SR33_STRICT"] = "1"

from hypothesis import HealthCheck, settings

settings.register_profile(
    "ci",
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("deep", max_examples=1000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
