"""seisrack.motion"""
