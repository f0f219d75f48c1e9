"""What a run leaves behind, and reading it again: the run folder, the figures, the verdicts.

    run_folder.py   the run folder, written as the run goes (`g1 launch`, `g1 deploy`)
    results.py      a run's figures from its log (velocity per segment, upper body, timings,
                    falls), its summary.json and its printed report
    outcomes.py     goals judged from the simulator's ground truth (hands, boxes, feet)
    verdict.py      Verdict: met or missed, with the figures (program steps, bench rows)
    plots.py        velocity.png
    overlay.py      the text over the viewer and the video
    replay.py       `g1 replay RUN`, `g1 view CLIP`
"""
