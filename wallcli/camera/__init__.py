"""What the camera and recorder did to the picture, found and taken out before the plots: repeated frames, overlays, interlacing, noise reduction, white balance, exposure, shake."""
