"""Byte helpers shared by every stage: number formatting, XML/JSON/STL writers, kit paths,
archives, packaged data and the content-addressed cache. Imports nothing from simkit's stages."""
