"""The class's marks in the layout of Canvas's gradebook (its export, re-imported).

Written by ``python -m grading batch --gradebook`` (:mod:`grading.instructors.batch`).

Students choose their Gradescope SIDs and emails, so a submission's claims
to a roster row are never trusted to be unique: a match is kept only when
it is unambiguous (:func:`match_roster`), and every refusal is listed.
"""

import csv
from collections import defaultdict

from grading.instructors.reports import csv_report, say

GRADEBOOK_IDENTITY = ("Student", "ID", "SIS User ID", "SIS Login ID", "Section")  # Canvas's gradebook export
ROSTER_KEYS = ("SIS Login ID", "SIS User ID", "ID")  # the roster's columns a submission may be matched by


def claims(folder):
    """The identities each claimant of ``folder`` is known by: its folder's name, then one set per submitter.

    A submitter (from Gradescope's metadata) is known by the SID, the email
    and the email's login.
    """
    submitters = [
        (f"submitter {_person(p)}", {p["sid"], p["email"], p["email"].split("@")[0]} - {""}) for p in folder.submitters
    ]
    return [("the folder's name", {folder.name}), *submitters]


def _person(person):
    return f"{person['name']} <{person['email']}> {person['sid']}".strip()


def _row(student):
    return f"{student.get('Student', '').strip()} [{student.get('SIS Login ID', '').strip()}]"


def match_roster(folders, students):
    """Match submissions to roster rows, refusing every ambiguous match.

    A claimant (a folder's name, or one submitter) matches the rows whose
    SIS Login ID, SIS User ID or ID is one of its identities
    (:func:`claims`). A folder whose claimant matches several rows is
    refused (a student's choice of SID or email must not reach a
    classmate's row), and so is any row matched by several folders: neither
    is guessed. A group's folder matches one row per submitter.

    Parameters
    ----------
    folders : list of grading.instructors.batch.Folder
    students : list of dict
        The roster's rows (a Canvas gradebook export, read as dictionaries).

    Returns
    -------
    matched : dict
        Row index -> the one folder that holds its mark.
    problems : list of str
        One line per refused folder, refused row, and folder in no row.
    """
    rows_by_key = defaultdict(set)
    for index, student in enumerate(students):
        for column in ROSTER_KEYS:
            key = student.get(column, "").strip()
            if key:
                rows_by_key[key].add(index)
    problems, refused, folders_by_row = [], set(), defaultdict(list)
    for position, folder in enumerate(folders):
        rows = set()
        for who, identities in claims(folder):
            hits = set().union(*(rows_by_key.get(key, set()) for key in identities))
            if len(hits) > 1:
                refused.add(position)
                shown = ", ".join(_row(students[i]) for i in sorted(hits))
                problems.append(
                    f"{folder.name}: refused, ambiguous: {who} matches {len(hits)} roster rows ({shown}): "
                    "no mark given from this submission"
                )
            rows |= hits
        for index in rows:
            folders_by_row[index].append(position)
        if not rows:
            problems.append(
                f"{folder.name}: in no roster row (by SIS Login ID, SIS User ID or ID): not in the gradebook file"
            )
    matched = {}
    for index, positions in sorted(folders_by_row.items()):
        if len(positions) > 1:
            shown = ", ".join(folders[p].name for p in positions)
            problems.append(
                f"{_row(students[index])}: refused, ambiguous: matched by {len(positions)} submissions ({shown}): "
                "left empty in the gradebook file"
            )
        elif positions[0] not in refused:
            matched[index] = folders[positions[0]]
    return matched, problems


def read_roster(roster):
    """The students of a Canvas gradebook export (its ``Points Possible`` row aside)."""
    try:
        with open(roster, newline="", encoding="utf-8-sig") as handle:
            rows = list(csv.DictReader(handle))
    except UnicodeDecodeError:
        raise SystemExit(f"error: the roster {roster} is not UTF-8: export it from the gradebook") from None
    students = [row for row in rows if (row.get("Student") or "").strip() != "Points Possible"]
    missing = [column for column in GRADEBOOK_IDENTITY if students and column not in students[0]]
    if missing:
        raise SystemExit(f"error: the roster {roster} has no column {', '.join(missing)}: export it from the gradebook")
    return [{key: value or "" for key, value in row.items() if isinstance(key, str)} for row in students]


def write_gradebook(path, assignment, folders, roster=None):
    """Write the marks in the layout of Canvas's gradebook (its export, re-imported).

    Columns ``Student, ID, SIS User ID, SIS Login ID, Section`` and one
    column ``assignment`` holding each total, after a ``Points Possible``
    row. With ``roster`` (a gradebook exported from the course), each
    submission is matched to the student whose SIS Login ID, SIS User ID or
    ID is its folder's name or, with Gradescope's metadata, a submitter's
    SID, email or email login, only when that match is unambiguous
    (:func:`match_roster`: every refusal is printed); every identity column
    is copied from the roster. A folder that held nothing gradable, or was
    refused, scores 0, as on Gradescope (marks.csv says why); students
    without a folder, or whose match was refused, get an empty cell (no
    change on import). Without a roster, one row per folder (per submitter,
    with metadata). Every cell is written by
    :func:`grading.instructors.reports.csv_report` (never a formula).

    Returns
    -------
    list of str
        The lines printed about submissions or rows left out.
    """
    possible = max((f.grading.max_score for f in folders if f.grading), default=0)

    def mark(folder):
        return f"{folder.grading.score:g}" if folder.grading else "0"

    rows, problems = [], []
    if roster:
        students = read_roster(roster)
        matched, problems = match_roster(folders, students)
        for index, student in enumerate(students):
            folder = matched.get(index)
            rows.append([*(student.get(c, "") for c in GRADEBOOK_IDENTITY), mark(folder) if folder else ""])
    else:
        for folder in folders:
            people = folder.submitters or [{"name": folder.name, "sid": "", "email": folder.name}]
            rows += [[p["name"], "", p["sid"], p["email"] or folder.name, "", mark(folder)] for p in people]
    with csv_report(path) as writer:
        writer.writerow([*GRADEBOOK_IDENTITY, assignment])
        writer.writerow(["Points Possible", "", "", "", "", f"{possible:g}"])
        writer.writerows(rows)
    for line in problems:
        say(line)
    say(f"Gradebook (Canvas layout, column {assignment!r}) written to {path}")
    return problems
