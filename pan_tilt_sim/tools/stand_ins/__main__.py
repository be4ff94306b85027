"""``python -m pan_tilt_sim.tools.stand_ins NAME ARGS``: run the stand-in NAME."""

from pan_tilt_sim.tools.stand_ins import main

if __name__ == '__main__':
    main()
