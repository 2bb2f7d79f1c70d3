"""The class's marks in the layout of Canvas's gradebook (its export, re-imported).

Written by ``python -m grading batch --gradebook`` (:mod:`grading.instructors.batch`).
"""

import csv

GRADEBOOK_IDENTITY = ("Student", "ID", "SIS User ID", "SIS Login ID", "Section")  # Canvas's gradebook export


def write_gradebook(path, assignment, folders, roster=None):
    """Write the marks in the layout of Canvas's gradebook (its export, re-imported).

    Columns ``Student, ID, SIS User ID, SIS Login ID, Section`` and one
    column ``assignment`` holding each total, after a ``Points Possible``
    row. With ``roster`` (a gradebook exported from the course), each
    submission is matched to the student whose SIS Login ID, SIS User ID or
    ID is its folder's name or, with Gradescope's metadata, a submitter's
    SID, email or email login; every identity column is copied from the
    roster. A folder that held nothing gradable, or was refused, scores 0,
    as on Gradescope (marks.csv says why); students without a folder get an
    empty cell (no change on import). Without a roster, one row per folder
    (per submitter, with metadata).
    """
    possible = max((f.grading.max_score for f in folders if f.grading), default=0)

    def mark(folder):
        return f"{folder.grading.score:g}" if folder.grading else "0"

    rows = []
    if roster:
        with open(roster, newline="", encoding="utf-8-sig") as handle:
            students = [row for row in csv.DictReader(handle) if row.get("Student", "").strip() != "Points Possible"]
        missing = [column for column in GRADEBOOK_IDENTITY if students and column not in students[0]]
        if missing:
            raise SystemExit(
                f"error: the roster {roster} has no column {', '.join(missing)}: export it from the gradebook"
            )
        matched = set()
        for student in students:
            keys = {student.get(c, "").strip() for c in ("SIS Login ID", "SIS User ID", "ID")} - {""}
            folder = next((f for f in folders if f.identities() & keys), None)
            matched.add(folder.name if folder else None)
            rows.append([*(student.get(c, "") for c in GRADEBOOK_IDENTITY), mark(folder) if folder else ""])
        for folder in folders:
            if folder.name not in matched:
                print(
                    f"{folder.name}: in no roster row (by SIS Login ID, SIS User ID or ID): not in the gradebook file"
                )
    else:
        for folder in folders:
            people = folder.submitters or [{"name": folder.name, "sid": "", "email": folder.name}]
            rows += [[p["name"], "", p["sid"], p["email"] or folder.name, "", mark(folder)] for p in people]
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow([*GRADEBOOK_IDENTITY, assignment])
        writer.writerow(["Points Possible", "", "", "", "", f"{possible:g}"])
        writer.writerows(rows)
    print(f"Gradebook (Canvas layout, column {assignment!r}) written to {path}")
