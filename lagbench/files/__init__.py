"""The ground floor: result files (results.py), the folder lock (folder_lock.py), the time they record
(clock.py), and the boundaries with a user's code (user_functions.py) and data files (user_data.py). Imports
nothing of the suite above it, so every package may import it (tests/test_floors.py)."""
