import sys

from grading import grader_links

if links := grader_links():  # before another module of the grader is imported
    sys.exit(f"error: refusing to run: the grader holds a link or special file: {links[0]}")

from grading.cli import main  # noqa: E402

sys.exit(main())
