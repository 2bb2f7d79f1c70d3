"""The instructors' tools: never in a student's copy of the grader.

* :mod:`~grading.instructors.commands` -- ``batch``, ``release``, ``gradescope``,
  ``autograde`` and ``similarity``, read by :mod:`grading.cli`.
* :mod:`~grading.instructors.batch` and :mod:`~grading.instructors.gradebook` --
  a class graded on one machine, its marks and its Canvas gradebook.
* :mod:`~grading.instructors.gradescope` -- the Gradescope archive, and ``autograde`` inside it.
* :mod:`~grading.instructors.release` -- the student repository;
  :mod:`~grading.instructors.shipping` what a copy of the course withholds;
  :mod:`~grading.instructors.leakcheck` the scan for the reference's code.
* :mod:`~grading.instructors.similarity` -- the similarity report of a class (copydetect).
* :mod:`~grading.instructors.mistakes` -- the catalogue of known mistakes,
  one module per exercise module (it computes right answers).
* :mod:`~grading.instructors.trees` -- lecture 2's canonical trees and the
  lying trees of its structure tests (they answer its exercises).
* ``templates/`` -- the student repository's and Gradescope's own files.

The student release withholds this folder whole, and its absence is what
makes a copy a student's (:func:`grading.instructors_grader`).
"""
