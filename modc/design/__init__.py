"""Task-based design: `modc design FILE -o DIR` finds module chains for a `design` block's cell.

    space.py     the design space under the paper's rules, shapes and the exact reductions
    batch.py     The paper's kinematics (docs/conventions.md) for many candidates and joint vectors at once (numpy)
    reach.py     batched damped-least-squares IK (position or 6-D) within the joint limits
    screen.py    cheap screens: reach bound, sphere-swept obstacle test, static torques at poses
    evaluate.py  screen_batch (the fast screen) and verify (the exact check with modc's analyses)
    search.py    per shape: exhaustive twist enumeration or CMA-ES; a pure function of its inputs
    run.py       shapes by size and mass on any concurrent.futures executor, exact checks in order
    rank.py      the objectives' order, the Pareto front
    write.py     ranking.json, one robot .mod per design, report.json
    report.py    report.html (ranking, Pareto plot as inline SVG, pictures)
"""
