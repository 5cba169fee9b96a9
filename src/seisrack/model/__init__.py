"""seisrack.model"""
