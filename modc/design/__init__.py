"""Task-based design: `modc design FILE -o DIR` finds module chains for a `design` block's cell.

    space.py     the design space under the paper's rules, shapes and the exact reductions
    bounds.py    sound bounds: twist settings and targets no joint vector can serve, without IK
    batch.py     The paper's kinematics (docs/conventions.md) for many candidates and joint vectors at once (numpy)
    reach.py     batched damped-least-squares IK (position or 6-D) within the joint limits
    screen.py    cheap screens: reach bound, sphere-swept obstacle test, static torques at poses
    evaluate.py  screen_batch (the fast screen) and verify (the exact check with modc's analyses)
    search.py    per shape: every twist setting, screened or excluded by a bound, in ranges of settings
    run.py       shapes by size and mass on any concurrent.futures executor; budget, Ctrl-C, progress
    verify_order.py  exact checks in ranking order; H/L swaps of one arm as its alternatives
    tasks.py     the cell's tasks and paths planned and timed (modc.plan.task) for the designs returned
    diagnose.py  why no design: per target, reach, obstacles, joint limits or torque
    rank.py      the objectives' registry and order, the Pareto front
    write.py     ranking.json, one robot .mod per design, report.json
    report.py    report.html (ranking, Pareto plot as inline SVG, pictures)
"""
