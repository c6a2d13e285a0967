# SPDX-License-Identifier: MIT
"""Examples: ``python3 -m wingman_lcm.examples.print_targets`` and ``python3 -m wingman_lcm.examples.log_summary``."""
