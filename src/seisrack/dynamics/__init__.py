"""seisrack.dynamics"""
