"""Test-wide settings: no progress bars in test output (replication.nav.parallel reads REPLICATION_PROGRESS)."""

import os

os.environ["REPLICATION_PROGRESS"] = "0"
