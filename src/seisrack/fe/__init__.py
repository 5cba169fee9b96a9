"""seisrack.fe"""
