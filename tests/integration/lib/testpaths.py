# SPDX-License-Identifier: GPL-2.0-or-later
"""Puts every folder of tests/integration on sys.path (Python 3 stdlib only).

The integration tests live by what they test (language/, ethercat/, protocols/, plugin/) and
their helpers in lib/; a test of one area may build on another's captures (test_quiet decodes
every rule file's), so a script puts lib/ on its path and imports this module:

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
    import testpaths  # noqa: E402,F401
"""

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

for name in sorted(os.listdir(ROOT)):
    folder = os.path.join(ROOT, name)
    if os.path.isdir(folder) and not name.startswith(("_", ".")) and folder not in sys.path:
        sys.path.append(folder)
