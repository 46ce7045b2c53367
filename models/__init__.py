"""The biped as a model file (biped.urdf) with its package.xml: package data, loaded by `package://` URI."""
