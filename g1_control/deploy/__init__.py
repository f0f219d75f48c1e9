"""`g1 deploy`: bring a G1 (or `g1 sim-robot`) under the control loop, safely.

preflight.py     the checklist that must pass (or be overridden, loudly) before anything moves
state_machine.py zero torque -> start -> ramp -> hold -> run -> control; damping on stop/fault/exit
backends.py      the robot link a launch file names (Unitree DDS, CAN, serial)
hands.py         the preflight's Dex3-1 hand rows (backend.hands: dex3) and the hand link
session.py       runs it all: preflight table, the loop, signals, the closing report
"""
